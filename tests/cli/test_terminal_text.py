"""What the terminal shows (issue 18): a name cannot forge a line, a failing quiet run still says why,
nothing is wrapped into pieces when output is not a terminal, a deep property is a located error, and
the command line speaks tablebot's words."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from core_helpers import EXAMPLE
from tablebot import registry
from tablebot.cli import app
from tablebot.cli.common import err_console, print_diagnostic
from tablebot.diagnostics import Diagnostic
from tablebot.escape import plain, terminal
from txt_fake import FakeTxt

FORGED = "Bumber\nFAKE: error: forged line\r\u2028x"
EXPORTS = ", ".join(b.name for b in registry.backends("export"))  # --to's choices


def invoke(*args: object) -> tuple[int, str]:
    result = CliRunner().invoke(app, [str(a) for a in args])
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exc_info
    return result.exit_code, result.output


@pytest.fixture
def bot(tmp_path: Path) -> Path:
    shutil.copytree(EXAMPLE, tmp_path / "bot")
    return tmp_path / "bot"


def test_line_breaks_in_user_text_are_shown_not_obeyed() -> None:
    assert plain("a\nb\r\tc\x1b") == "a\\nb\\r\tc\\x1b"
    assert terminal("[b]x[/b]\n") == "\\[b]x\\[/b]\\n"
    assert "\n" not in plain(FORGED) and "\u2028" not in plain(FORGED)


def test_a_robot_name_with_a_line_break_forges_no_line(bot: Path) -> None:
    robot = bot / "robot.toml"
    robot.write_text(robot.read_text().replace('name = "BumberBot"', 'name = "Bumber\\nFAKE: error: forged line"'))
    table = bot / "table.csv"
    table.write_text(table.read_text().replace("M2_speed", "M2_speed,X9", 1))
    code, output = invoke("check", bot)  # an error message naming the robot
    assert code == 2 and "for robot Bumber\\nFAKE: error: forged line" in output
    assert not [line for line in output.splitlines() if line.startswith("FAKE")], output
    table.write_text(table.read_text().replace("M2_speed,X9", "M2_speed", 1))
    code, output = invoke("check", bot)  # the report's first line names the robot too
    assert code == 0 and "robot Bumber\\nFAKE: error: forged line;" in output
    assert not [line for line in output.splitlines() if line.startswith("FAKE")], output


def test_a_tools_own_output_prints_below_its_diagnostic_marked_as_part_of_it() -> None:
    with err_console.capture() as captured:
        print_diagnostic(
            Diagnostic(
                "avr-gcc", None, None, "avr-gcc failed", "report this", detail="tb.c:3: error: x\ntb.c:4: note: y"
            )
        )
    assert captured.get().splitlines() == [
        "avr-gcc: error: avr-gcc failed",
        "    hint: report this",
        "    | tb.c:3: error: x",
        "    | tb.c:4: note: y",
    ]


def test_a_quiet_run_that_fails_still_says_why(tmp_path: Path) -> None:
    with FakeTxt(fault=("silent", 20)) as fake:
        result = CliRunner().invoke(
            app,
            [
                "run",
                str(EXAMPLE),
                "--on",
                f"txt://127.0.0.1:{fake.port}",
                "-q",
                "--seconds",
                "5",
                "--link-timeout",
                "0.1",
                "--out",
                str(tmp_path),
            ],
        )
    assert result.exit_code == 3
    assert "ran 20 ticks: link_lost — no answer from" in result.stderr
    assert f"kept {tmp_path / 'trace.partial.jsonl'}" in result.stderr
    assert result.stdout == ""  # quiet: no summary
    with FakeTxt() as fake:
        result = CliRunner().invoke(
            app, ["run", str(EXAMPLE), "--on", f"txt://127.0.0.1:{fake.port}", "-q", "--seconds", "0.1"]
        )
    assert result.exit_code == 0 and result.output == ""  # a run that succeeds stays silent


def test_paths_are_never_wrapped_when_output_is_not_a_terminal(bot: Path, tmp_path: Path) -> None:
    deep = tmp_path / ("a-rather-long-folder-name-" * 3) / ("and-another-one-beneath-it-" * 3)
    deep.mkdir(parents=True)
    code, output = invoke("trace", bot, "--inputs", bot / "inputs.csv", "--out", deep / "trace.jsonl")
    assert code == 0 and f"wrote {deep / 'trace.jsonl'} (3000 ticks)" in output.splitlines()
    code, output = invoke("check", deep / "missing.csv")
    assert code == 2 and any(line.startswith(f"{deep / 'missing.csv'}: error:") for line in output.splitlines())


def test_a_deeply_nested_property_is_a_located_error_and_a_long_flat_one_works(bot: Path) -> None:
    """300 nested parentheses (or 'not's) ended with RecursionError (exit 70); so did an 'or' of 1,000 terms."""
    deep = "(" * 300 + "I3" + ")" * 300
    (bot / "properties.toml").write_text(f'[deep]\nnever = "{deep}"\n\n[negated]\nnever = "{"not " * 400}I3"\n')
    code, output = invoke("check", bot)
    assert code == 2 and "Traceback" not in output and "internal error" not in output
    assert f"{bot / 'properties.toml'}:1: error: property deep: never: the condition nests parentheses" in output
    assert f"{bot / 'properties.toml'}:4: error: property negated" in output
    flat = " or ".join(["state == 20"] * 1000)
    every = " and ".join(["I3"] * 1000)
    (bot / "properties.toml").write_text(
        f'[flat]\nnever = "{flat}"\nlevel = "warning"\n\n[every]\nnever = "{every} and M1 > 8"\n'
    )
    code, output = invoke("check", bot)
    assert code == 0, output
    assert "VIOLATED flat" in output and "holds    every" in output


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (
            ["new", "x", "--from", "nothing"],
            "--from: error: 'nothing' is not one of the choices of --from\n"
            "    hint: use one of: bumberbot, line-follower, obstacle-avoider, empty",
        ),
        (
            ["export", str(EXAMPLE), "out", "--to", "cc"],
            f"--to: error: 'cc' is not one of the choices of --to\n    hint: use one of: {EXPORTS}",
        ),
        (["export", str(EXAMPLE), "out"], f"--to: error: --to is missing\n    hint: give --to one of: {EXPORTS}"),
        (["sim", str(EXAMPLE), "--seconds", "abc"], "--seconds: error: 'abc' is not a number"),
        (
            ["sim", str(EXAMPLE), "--seconds", "9999"],
            "--seconds: error: --seconds 9999 is out of range\n    hint: give --seconds a value from 0.01 to 3600",
        ),
        (
            ["sim", str(EXAMPLE), "--battery", "nan"],
            "--battery: error: --battery nan is not a finite number\n    hint: give --battery a value from 0.0 to 1.0",
        ),
        (["sweep", str(EXAMPLE), "--seconds", "inf"], "--seconds: error: --seconds inf is not a finite number"),
        (
            ["run", str(EXAMPLE), "--on", "sim", "--seconds", "0.3", "-q", "--behind-limit", "nan"],
            "--behind-limit: error: --behind-limit nan is not a finite number\n"
            "    hint: give --behind-limit a value of at least 0.0",
        ),
        (
            ["sim", str(EXAMPLE), "--sed", "3"],
            "--sed: error: --sed is not an option of this command\n    hint: did you mean --seconds or --seed?",
        ),
        (["chek", str(EXAMPLE)], "chek: error: 'chek' is not a tablebot command\n    hint: did you mean check?"),
        (["new"], "FOLDER: error: FOLDER is missing"),
    ],
)
def test_a_wrong_command_line_is_answered_in_tablebots_words(args: list[str], words: str) -> None:
    """`new x --from nothing` answered "Invalid value for '--from': Value error, 'nothing' is not one of ..."."""
    code, output = invoke(*args)
    assert code == 2 and words in output, output
    assert "Value error" not in output and "Input should be" not in output and "Usage:" not in output


def test_no_number_option_of_any_command_takes_nan_or_inf() -> None:
    """click's range test let nan through (every comparison with it is false): `sim --battery nan` simulated
    a robot without charge, `sweep --seconds nan` ended in an internal error."""
    import typer.main
    from typer._click.exceptions import BadParameter
    from typer._click.types import FloatParamType

    from tablebot.cli.app import app

    group = typer.main.get_command(app)
    options = [
        (name, param)
        for name, command in group.commands.items()  # type: ignore[attr-defined]
        for param in command.params
        if isinstance(param.type, FloatParamType)
    ]
    assert len(options) == 9  # sim, sweep, tune, evolve, run, monitor: their --seconds, and four more
    for name, param in options:
        for text in ("nan", "-inf", "inf", "NaN"):
            with pytest.raises(BadParameter, match="is not a finite number"):
                param.type.convert(text, param, None)
        low = getattr(param.type, "min", None)
        assert param.type.convert(repr(low or 1.0), param, None) == (low or 1.0), name  # its range, as before


def test_export_offers_no_force_and_never_suggests_it(tmp_path: Path) -> None:
    """export --force was offered but changed nothing an export writes."""
    assert not re.search(r"^\s+--force", invoke("export", "-h")[1], re.MULTILINE)
    (tmp_path / "event.csv").write_bytes((EXAMPLE / "table.csv").read_bytes())  # a table of yours, named like a list
    code, output = invoke("export", EXAMPLE, tmp_path, "--to", "robopro")
    assert code == 2 and "event.csv exists and is a table file: this command never replaces it" in output
    assert "--force" not in output
    assert (tmp_path / "event.csv").read_bytes() == (EXAMPLE / "table.csv").read_bytes()


def test_the_first_simulation_says_it_is_compiling(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from tablebot import jit

    invoke("sim", EXAMPLE, "--seconds", "0.5", "--no-plots", "-q", "--out", tmp_path / "first")  # compiled now
    code, output = invoke("sim", EXAMPLE, "--seconds", "0.5", "--no-plots", "-q", "--out", tmp_path / "warm")
    assert code == 0 and "compiling" not in output  # in the cache: nothing to say
    monkeypatch.setattr(jit, "compiled", lambda *functions: False)  # as on a machine that never ran it
    code, output = invoke("sim", EXAMPLE, "--seconds", "0.5", "--no-plots", "-q", "--out", tmp_path / "cold")
    assert code == 0 and "compiling the simulator for this machine (first run only" in output


def test_compiled_tells_a_cached_function_from_one_still_to_compile(tmp_path: Path) -> None:
    """Against numba's real on-disk cache, in a process of its own with an empty cache folder."""
    import os
    import subprocess
    import sys

    (tmp_path / "tiny.py").write_text("from tablebot.jit import njit\n\n@njit\ndef add(x):\n    return x + 1\n")
    script = (
        "import tiny; from tablebot.jit import compiled\n"
        "print(compiled(tiny.add)); tiny.add(1); print(compiled(tiny.add))\n"
    )
    root = Path(__file__).resolve().parents[2]
    env = {
        **os.environ,
        "NUMBA_CACHE_DIR": str(tmp_path / "cache"),
        "PYTHONPATH": os.pathsep.join([str(tmp_path), str(root / "src")]),
    }
    done = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=120)
    assert done.stdout.split() == ["False", "True"], done.stderr


def test_demo_replays_into_a_folder_of_its_own(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """`tablebot demo` wrote its replay trace into out/demo, beside the pictures `make demo` simulates."""
    monkeypatch.chdir(tmp_path)
    code, output = invoke("demo")
    assert code == 0, output
    assert (tmp_path / "out" / "replay" / "trace.jsonl").is_file() and not (tmp_path / "out" / "demo").exists()
