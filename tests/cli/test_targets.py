"""The registry of back-ends: one fit check per target, shared by ``export`` and ``check --target``; the CLI's
choices come from it."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from core_helpers import EXAMPLE, ROOT, example_machine, machine_of
from tablebot import registry
from tablebot.cli.app import app
from tablebot.codegen.packing import MAX_EVENTS

pytestmark = [pytest.mark.kernel_free]

WIDE_ROBOT = (
    'name = "Wide"\ninitial_state = 1\n[inputs]\n'
    + "".join(f'I{i} = ""\n' for i in range(MAX_EVENTS))
    + '[motors]\nM1 = ""\n'
)
WIDE_TABLE = f"state,T,{','.join(f'I{i}' for i in range(MAX_EVENTS))},M1,timer,next\n1,1{',' * MAX_EVENTS},1,5,1\n"


@pytest.mark.parametrize("name", registry.check_targets())
def test_the_bumberbot_fits_every_target(name: str) -> None:
    assert registry.get(name).problems(example_machine()) == []


def test_a_table_too_wide_for_c_is_refused_by_c_and_the_boards_alike(tmp_path: Path) -> None:
    machine = machine_of(tmp_path, WIDE_TABLE, WIDE_ROBOT)
    for name in ("c", "uno", "ftduino"):
        problems = registry.get(name).problems(machine)
        assert problems and f"the C engine holds at most {MAX_EVENTS}" in problems[0].message, name


def test_check_target_reports_what_export_refuses(tmp_path: Path) -> None:
    table = tmp_path / "table.csv"
    machine_of(tmp_path, WIDE_TABLE, WIDE_ROBOT)
    runner = CliRunner()
    checked = runner.invoke(app, ["check", str(table), "--target", "c"])
    exported = runner.invoke(app, ["export", str(table), str(tmp_path / "c"), "--to", "c"])
    assert checked.exit_code == 2 and exported.exit_code == 2
    assert f"c: {MAX_EVENTS + 1} event columns" in checked.output
    assert f"{MAX_EVENTS + 1} event columns; the C engine holds at most {MAX_EVENTS}" in exported.output
    assert not (tmp_path / "c").exists()


def test_a_robot_without_txt_wiring_does_not_fit_the_txt_targets() -> None:
    from tablebot.cli.common import load

    _, machine = load(ROOT / "examples" / "bumberbot-counters")
    for name in ("txt", "txt4"):
        problems = registry.get(name).problems(machine)
        assert any("has no [txt] section" in p.message for p in problems), name


def test_unknown_target_names_the_known_ones() -> None:
    result = CliRunner().invoke(app, ["check", str(EXAMPLE), "--target", "arduino"])
    assert result.exit_code == 2 and "unknown export target 'arduino'" in result.output
    assert all(name in result.output for name in registry.check_targets())


def test_the_commands_choices_are_the_registered_back_ends() -> None:
    """--to, --board, --on and check --target list exactly what is registered, in its order."""
    runner = CliRunner()
    assert registry.names("export") == ["robopro", "robopro-rpp", "robopro-program", "c", "scxml", "xstate", "txt4"]
    assert registry.names("board") == ["uno", "ftduino"]
    assert registry.names("live") == ["txt", "robotx", "roboif", "sim"]
    assert registry.check_targets() == [
        "robopro",
        "robopro-rpp",
        "robopro-program",
        "c",
        "uno",
        "ftduino",
        "txt",
        "robotx",
        "roboif",
        "txt4",
    ]
    from tablebot.cli.export import Target
    from tablebot.cli.firmware import BoardName

    assert [t.value for t in Target] == registry.names("export")
    assert [b.value for b in BoardName] == registry.names("board")
    on = runner.invoke(app, ["run", str(EXAMPLE), "--on", "nowhere://x"])
    assert on.exit_code == 2 and "robotx://auto" in on.output and "roboif://auto" in on.output
    assert "sim or sim:WORLD.toml" in on.output


def test_a_back_end_registers_once_and_says_what_it_is() -> None:
    c = registry.get("c")
    assert registry.register(c) is c  # registering the same one again is harmless
    assert isinstance(c, registry.ExportBackend) and c.kind == "export"
    with pytest.raises(ValueError, match="two back-ends"):
        registry.register(registry.ExportBackend(name="c", makes="another", export=c.export))
    with pytest.raises(TypeError, match="an ExportBackend or a LiveBackend"):
        registry.register(object())  # type: ignore[type-var]
    sim = registry.get("sim")
    assert isinstance(sim, registry.LiveBackend) and sim.kind == "live" and registry.exporter("sim") is None
    assert [b.name for b in registry.lives()] == registry.names("live")
    assert [b.name for b in registry.exporters("board")] == registry.names("board") == ["uno", "ftduino"]
