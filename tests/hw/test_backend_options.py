"""Each option of ``run`` and ``export`` reaches the back-end that uses it, by name (tablebot.registry's
LinkOptions and ExportOptions): ``--link-timeout`` is the timeout of the real link, against the controllers'
emulators (ROBO TX and ROBO Interface on a real pseudo-terminal, the TXT on loopback TCP); ``--seed`` is the
simulator's; ``--lookup``, ``--into`` and the list names are the exporters'. Export and live back-ends are
separate types: each is asked only what its kind does."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import pytest
from typer.testing import CliRunner

from core_helpers import EXAMPLE
from tablebot import registry
from tablebot.cli import app
from tablebot.hw.link_speed import PROBES
from tablebot.testing.roboif_emulator import RoboifEmulator
from tablebot.testing.robotx_emulator import RobotxEmulator
from txt_fake import FakeTxt

if TYPE_CHECKING:
    from contextlib import AbstractContextManager

    from typer.testing import Result

runner = CliRunner()
RPP = Path(__file__).resolve().parents[1] / "fixtures" / "rpp" / "engine.rpp"
SILENT_FROM = PROBES + 12  # the link is timed first (PROBES exchanges), then the run's exchanges begin


def invoke(*args: object) -> Result:
    return runner.invoke(app, [str(a) for a in args])


def silent_controller(kind: str) -> tuple[AbstractContextManager, str]:
    """A controller that stops answering a few ticks into the run, and the ``--on`` address that reaches it."""
    if kind == "txt":
        fake = FakeTxt(fault=("silent", SILENT_FROM))
        return fake, f"txt://127.0.0.1:{fake.port}"
    emulator = (RobotxEmulator if kind == "robotx" else RoboifEmulator)(fault=("silent", SILENT_FROM))
    return emulator, f"{kind}://{emulator.device}"


@pytest.mark.parametrize("kind", ["robotx", "roboif", "txt"])
def test_link_timeout_is_the_real_links_timeout(kind: str) -> None:
    """The run ends as link_lost after exactly the timeout given (the link says how long it waited), and after
    5 ticks without the option; the controller's outputs are off at the end either way."""
    said = {}
    for timeout in ("0.37", None):
        controller, address = silent_controller(kind)
        with controller:
            done = invoke(
                "run",
                EXAMPLE,
                "--on",
                address,
                "--seconds",
                "2",
                "--behind-limit",
                "0",
                *(["--link-timeout", timeout] if timeout else []),
            )
        assert done.exit_code == 3, done.output
        said[timeout] = " ".join(done.output.split())
    assert "link_lost" in said["0.37"] and "within 370 ms" in said["0.37"] and "within 50 ms" not in said["0.37"]
    assert "link_lost" in said[None] and "within 50 ms" in said[None]  # 5 ticks of 10 ms


def test_behind_limit_zero_reaches_the_links_judge() -> None:
    """A ROBO Interface at 38400 baud is too slow for a 10 ms tick: refused, unless --behind-limit 0 accepts
    slow timers (then it runs, and says so)."""
    said = {}
    for extra in ([], ["--behind-limit", "0"]):
        with RoboifEmulator(baud=38400) as emu:
            said[bool(extra)] = invoke(
                "run", EXAMPLE, "--on", f"roboif://{emu.device}", "--seconds", "0.1", "--link-timeout", "0.5", *extra
            )
    refused, accepted = said[False], said[True]
    assert refused.exit_code == 2 and "accept timers" in refused.output and "--behind-limit 0" in refused.output
    assert accepted.exit_code == 0, accepted.output
    assert "running anyway (--behind-limit 0)" in " ".join(accepted.output.split())


def test_link_options_say_what_a_live_back_end_is_given() -> None:
    link = registry.LinkOptions("robotx://auto", link_timeout_s=0.37, behind_limit_s=0.0, seed=4)
    assert link.timeout_s(0.01) == 0.37 and registry.LinkOptions("sim").timeout_s(0.02) == pytest.approx(0.1)
    assert link.accept_slow and not registry.LinkOptions("sim").accept_slow
    assert link.hint_or("its own") == "its own" and registry.LinkOptions("x", hint="all").hint_or("own") == "all"


def test_seed_reaches_the_simulated_robot() -> None:
    done = invoke("run", EXAMPLE, "--on", "sim", "--seconds", "0.03", "--seed", "7")
    assert done.exit_code == 0, done.output
    assert "(simulated, seed 7)" in done.output and "ran 3 ticks" in done.output


def test_lookup_reaches_the_c_generator(tmp_path: Path) -> None:
    for lookup in ("scan", "dense"):
        done = invoke("export", EXAMPLE, tmp_path / lookup, "--to", "c", "--lookup", lookup)
        assert done.exit_code == 0, done.output
        assert f"lookup: {lookup}," in done.output
    assert (tmp_path / "scan" / "tb_table.c").read_bytes() != (tmp_path / "dense" / "tb_table.c").read_bytes()


def test_into_and_the_list_names_reach_the_rpp_writer(tmp_path: Path) -> None:
    done = invoke("export", EXAMPLE, tmp_path, "--to", "robopro-rpp", "--into", RPP)
    assert done.exit_code == 0 and "lists Event, Action, Timer" in done.output, done.output
    renamed = invoke(
        "export", EXAMPLE, tmp_path / "other", "--to", "robopro-rpp", "--into", RPP, "--event-list", "Other"
    )
    assert renamed.exit_code == 0 and "lists Other, Action, Timer" in renamed.output, renamed.output
    missing = invoke("export", EXAMPLE, tmp_path / "none", "--to", "robopro-rpp", "--into", RPP, "--timer-list", "Uhr")
    assert missing.exit_code == 2 and "no list named 'Uhr'" in missing.output
    nowhere = invoke("export", EXAMPLE, tmp_path, "--to", "robopro-rpp")
    assert nowhere.exit_code == 2 and nowhere.output.startswith("--into: error:")


def test_export_and_live_back_ends_are_separate_types() -> None:
    for backend in registry.backends():
        live = isinstance(backend, registry.LiveBackend)
        assert live == (backend.kind == "live") and live != isinstance(backend, registry.ExportBackend)
        assert callable(backend.open if isinstance(backend, registry.LiveBackend) else backend.export)
    assert registry.exporter("txt") is None and registry.live_for("c://x") is None
    assert isinstance(registry.live_for("txt://auto"), registry.LiveBackend)
    board = registry.exporter("uno")
    assert board is not None and board.kind == "board" and board.board
    with pytest.raises(TypeError, match="positional"):
        registry.ExportBackend("c", "again", export=board.export)  # type: ignore[call-arg]
