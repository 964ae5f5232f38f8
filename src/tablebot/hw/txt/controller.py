"""A fischertechnik TXT (or a TXT 4.0 running ftrobopy_server) as a :class:`tablebot.loop.RobotIO`:
one ExchangeData per engine tick, outputs off on every way out.

Each tick's ``write`` sends the engine's outputs at once and keeps the reply, whose inputs the next
``read`` returns: the engine sees inputs one exchange old (the TXT samples them for its reply) and its
decisions reach the motors without waiting a tick. ``open`` makes a first exchange with the outputs
off, so tick 0 has inputs too.
"""

from __future__ import annotations

from collections.abc import Sequence

from tablebot.hw.exchange import ExchangeRobot
from tablebot.hw.txt import protocol as wire
from tablebot.hw.txt.link import TxtLink
from tablebot.hw.txt.protocol import Command
from tablebot.hw.txt.wiring import TxtWiring
from tablebot.i18n import N_
from tablebot.loop import LinkLost, Reading

ZERO = [0] * wire.N_OUTPUTS


class FirmwareTooOld(LinkLost):
    """The controller answered, with firmware older than fischertechnik's own online client accepts."""


class TxtRobot(ExchangeRobot):
    """The robot behind ``host:port``; a reply missing for ``link_timeout_s`` (or malformed) ends the run."""

    def __init__(
        self,
        wiring: TxtWiring,
        host: str,
        port: int = wire.PORT,
        *,
        link_timeout_s: float = 0.05,
        client_name: str = "tablebot",
    ) -> None:
        self.wiring = wiring
        self.link = TxtLink(host, port, reply_timeout_s=link_timeout_s)
        self.client_name = client_name
        self.status: wire.Status | None = None
        super().__init__()

    @property
    def target(self) -> str:
        return f"txt://{self.link.where}"

    def connect(self, timeout_s: float = 3.0) -> wire.Status:
        """Open the TCP connection and ask the controller who it is (nothing moves yet); firmware older
        than 4.6.6 is refused before going online, as fischertechnik's online client refuses it."""
        self.link.connect(timeout_s)
        self.status = self.link.query_status()
        if self.status.version < wire.MIN_VERSION:
            self.link.close()
            raise FirmwareTooOld(
                N_(
                    "{device} at {where} runs firmware {version} (0x{number:08X}); the online "
                    "protocol needs 4.6.6 or later, as fischertechnik's own online client checks",
                    device=self.status.device,
                    where=self.link.where,
                    version=self.status.version_text,
                    number=self.status.version,
                )
            )
        return self.status

    # --- RobotIO ----------------------------------------------------------------------------------

    def open(self) -> None:
        """Go online, configure inputs/outputs, and make a first exchange with every output off."""
        if self.link.sock is None:
            self.connect()
        else:
            self.link.keep_alive()
        self.link.start_online(self.client_name)
        self.link.update_config(self.wiring.config())
        self._first_exchange(self.wiring.counters)

    def close(self) -> None:
        """StopOnline (after :meth:`stop`'s zero exchange), then close the socket; never raises."""
        try:
            if self.link.online:
                self.link.send_best_effort(Command.STOP_ONLINE, wire.stop_online(), self._shutdown_s)
        except Exception:
            pass
        finally:
            self.link.close()

    # --- ExchangeRobot's hooks ----------------------------------------------------------------------

    OFF = ZERO

    def _command(self, outputs: Sequence[int]) -> list[int]:
        return self.wiring.pwm(outputs)

    def _exchange(self, command: list[int]) -> wire.Inputs:
        return self.link.exchange(command)

    def _send_off(self, timeout_s: float) -> None:
        self.link.send_best_effort(Command.EXCHANGE_DATA, wire.exchange(ZERO), timeout_s)

    def _reading_of(self, reply: wire.Inputs) -> Reading:
        previous = self._previous_mask()
        pulses = self._pulses(reply.counter_values, self.wiring.counters)
        return Reading(self.wiring.mask(reply.universal, previous), pulses, self.wiring.raw(reply.universal) or None)
