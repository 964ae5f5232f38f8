"""A ROBO TX Controller as a :class:`tablebot.loop.RobotIO`: one fish.X1 exchange per engine tick, outputs off
on every way out.

Each tick's ``write`` sends the engine's outputs at once and keeps the reply, whose inputs the next ``read``
returns: the engine decides on inputs one exchange old and its decisions reach the motors without waiting a
tick. ``open`` configures the inputs and makes a first exchange with every output off, so tick 0 has inputs.
"""

from __future__ import annotations

from collections.abc import Sequence

from tablebot.hw.exchange import ExchangeRobot
from tablebot.hw.robotx import protocol as wire
from tablebot.hw.robotx.link import RobotxLink
from tablebot.hw.robotx.wiring import RobotxWiring
from tablebot.loop import LinkLost, Reading

ZERO = [0] * wire.N_OUTPUTS


class RobotxRobot(ExchangeRobot):
    """The ROBO TX on serial ``device``; a reply missing for ``link_timeout_s`` (or malformed) ends the run."""

    def __init__(self, wiring: RobotxWiring, device: str, *, link_timeout_s: float = 0.05) -> None:
        self.wiring = wiring
        self.link = RobotxLink(device, reply_timeout_s=link_timeout_s)
        self.info: wire.Info | None = None
        super().__init__()

    @property
    def target(self) -> str:
        return f"robotx://{self.link.device}"

    def connect(self) -> wire.Info:
        """Open the port and ask the controller who it is (nothing moves yet)."""
        self.link.connect()
        try:
            self.info = self.link.hello()
        except LinkLost:
            self.link.close()
            raise
        return self.info

    # --- RobotIO ----------------------------------------------------------------------------------

    def open(self) -> None:
        """Configure inputs and outputs, then make a first exchange with every output off."""
        if not self.link.port.is_open:
            self.connect()
        self.link.configure(self.wiring.config())
        self._first_exchange(self.wiring.counters)

    def close(self) -> None:
        """Close the port (fish.X1 has no "go offline" command: the zero exchange of :meth:`stop` came first)."""
        self.link.close()

    # --- ExchangeRobot's hooks ----------------------------------------------------------------------

    OFF = ZERO

    def _command(self, outputs: Sequence[int]) -> list[int]:
        return self.wiring.duty(outputs)

    def _exchange(self, command: list[int]) -> wire.Inputs:
        return self.link.exchange(command)

    def _send_off(self, timeout_s: float) -> None:
        self.link.send_best_effort(ZERO, timeout_s)

    def _reading_of(self, reply: wire.Inputs) -> Reading:
        previous = self._previous_mask()
        return Reading(
            self.wiring.mask(reply, previous),
            self._pulses(reply.counter_values, self.wiring.counters),
            self.wiring.raw(reply) or None,
        )
