"""A ROBO Interface as a :class:`tablebot.loop.RobotIO`: one exchange per engine tick on its serial port,
outputs off on every way out.

Each tick's ``write`` sends the engine's outputs at once and keeps the reply, whose inputs the next ``read``
returns: the engine decides on inputs one exchange old. ``open`` makes a first exchange with every output
off, so tick 0 has inputs too. The ROBO Interface has no counters.
"""

from __future__ import annotations

from collections.abc import Sequence

from tablebot.hw.exchange import ExchangeRobot
from tablebot.hw.roboif import protocol as wire
from tablebot.hw.roboif.link import RoboifLink
from tablebot.hw.roboif.wiring import RoboifWiring
from tablebot.loop import LinkLost, Reading

OFF = (0, [0] * wire.N_OUTPUTS)


class RoboifRobot(ExchangeRobot):
    """The ROBO Interface on serial ``device``; a reply missing for ``link_timeout_s`` ends the run."""

    def __init__(self, wiring: RoboifWiring, device: str, *, link_timeout_s: float = 0.05) -> None:
        self.wiring = wiring
        self.link = RoboifLink(device, reply_timeout_s=link_timeout_s)
        self.greeting = b""
        super().__init__()

    @property
    def target(self) -> str:
        return f"roboif://{self.link.device}"

    def connect(self) -> bytes:
        """Open the port and greet the interface (nothing moves yet); LinkLost if it does not answer as one."""
        self.link.connect()
        try:
            self.greeting = self.link.hello()
        except LinkLost:
            self.link.close()
            raise
        return self.greeting

    # --- RobotIO ----------------------------------------------------------------------------------

    def open(self) -> None:
        if not self.link.port.is_open:
            self.connect()
        self._first_exchange()

    def close(self) -> None:
        """The farewell (after :meth:`stop`'s exchange with every output off), then the port closed."""
        self.link.close()

    # --- ExchangeRobot's hooks ----------------------------------------------------------------------

    OFF = OFF

    def _command(self, outputs: Sequence[int]) -> tuple[int, list[int]]:
        return self.wiring.outputs(outputs)

    def _exchange(self, command: tuple[int, list[int]]) -> wire.Inputs:
        return self.link.exchange(*command)

    def _send_off(self, timeout_s: float) -> None:
        self.link.send_best_effort(*OFF, timeout_s)

    def _reading_of(self, reply: wire.Inputs) -> Reading:
        previous = self._previous_mask()
        return Reading(self.wiring.mask(reply, previous), (), self.wiring.raw(reply) or None)
