"""An interrupted command leaves the complete old set of files or the complete new one, and no temporary
file (issue 18): every command that writes a set is interrupted at each of its file steps (the
``TABLEBOT_FAULT`` hook: the process sends itself SIGINT or SIGTERM there, through the real handlers),
real signals arrive at varied moments of real processes, and SIGKILL lands in the middle of a swap. The
harness (snapshots, the fault, the old-or-new check) is tests/interrupt_helpers.py."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from core_helpers import EXAMPLE
from interrupt_helpers import USER_FILE, check_outcome, interrupt_everywhere, invoke, leftovers, snapshot
from tablebot.files import write_text
from tablebot.fileset import file_set, recover
from tablebot.interrupts import FAULT_ENV, Terminated

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(autouse=True)
def sigterm_safe() -> Iterator[None]:
    """A SIGTERM that no command handles fails the test instead of ending pytest."""

    def escaped(signum: int, frame: object) -> None:
        raise Terminated("SIGTERM outside a command")

    previous = signal.signal(signal.SIGTERM, escaped)
    yield
    signal.signal(signal.SIGTERM, previous)


@pytest.fixture
def bot(tmp_path: Path) -> Path:
    shutil.copytree(EXAMPLE, tmp_path / "bot")
    return tmp_path / "bot"


@pytest.fixture
def named(tmp_path: Path) -> Path:
    """A table whose states have names: its lists come with states.csv."""
    folder = tmp_path / "named"
    folder.mkdir()
    (folder / "robot.toml").write_text(
        'name = "Named"\ninitial_state = "seek"\n[inputs]\nI3 = "bumper"\n[motors]\nM1 = "right"\nM2 = "left"\n'
    )
    (folder / "table.csv").write_text(
        "description,state,T,I3,M1_dir,M1_speed,M2_dir,M2_speed,timer,next\n"
        "seek,seek,1,,0,2,0,2,50,back\nback,back,1,,1,2,1,2,50,seek\n"
        ",back,,1,1,2,1,2,50,seek\n"
    )
    return folder


def test_export_robopro_leaves_the_old_lists_or_the_new(named: Path, tmp_path: Path) -> None:
    table = named
    outcomes = interrupt_everywhere(
        ["export", table, tmp_path / "lists", "--to", "robopro"], tmp_path / "lists", tmp_path / "ref"
    )
    assert outcomes == ["old"] * 4 + ["new"] * 4 + ["done"]  # four files written, then four renamed


def test_export_robopro_drops_a_states_csv_the_new_lists_have_no_names_for(
    bot: Path, named: Path, tmp_path: Path
) -> None:
    """An earlier export's states.csv beside lists of integer states would name them wrongly on import."""
    assert invoke(["export", named, tmp_path / "lists", "--to", "robopro"]) == 0
    assert (tmp_path / "lists" / "states.csv").exists()
    assert invoke(["export", bot, tmp_path / "lists", "--to", "robopro"]) == 0
    assert sorted(p.name for p in (tmp_path / "lists").iterdir()) == ["action.csv", "event.csv", "timer.csv"]


@pytest.mark.parametrize("target", ["c", "txt4"])
def test_export_c_and_txt4_leave_the_old_files_or_the_new(bot: Path, tmp_path: Path, target: str) -> None:
    outcomes = interrupt_everywhere(
        ["export", bot, tmp_path / "out", "--to", target], tmp_path / "out", tmp_path / "ref"
    )
    assert "old" in outcomes and "new" in outcomes and outcomes[-1] == "done"


def test_tests_and_counterexamples_leave_the_old_files_or_the_new(bot: Path, tmp_path: Path) -> None:
    outcomes = interrupt_everywhere(["tests", bot, "--out", tmp_path / "golden"], tmp_path / "golden", tmp_path / "ref")
    assert "old" in outcomes and "new" in outcomes
    (bot / "properties.toml").write_text(
        '[a]\nnever = "state == 20"\nlevel = "warning"\n[b]\nnever = "state == 21"\nlevel = "warning"\n'
    )
    outcomes = interrupt_everywhere(
        ["check", bot, "--counterexamples", tmp_path / "cex"], tmp_path / "cex", tmp_path / "ref-cex"
    )
    assert outcomes == ["old", "old", "new", "new", "done"]


def test_sim_leaves_the_old_run_or_the_new(bot: Path, tmp_path: Path) -> None:
    outcomes = interrupt_everywhere(
        ["sim", bot, "--seconds", "3", "--out", tmp_path / "s", "-q"], tmp_path / "s", tmp_path / "ref"
    )
    assert outcomes == ["old"] * 3 + ["new"] * 3 + ["done"]  # trace, trajectory, timeline


def test_new_makes_the_whole_folder_or_none(tmp_path: Path) -> None:
    outcomes = []
    for n in range(1, 10):
        code = invoke(["new", tmp_path / "robot"], f"{n}:{'INT' if n % 2 else 'TERM'}")
        assert not leftovers(tmp_path)
        made = sorted(p.name for p in (tmp_path / "robot").iterdir()) if (tmp_path / "robot").exists() else []
        assert made in ([], ["arena.toml", "properties.toml", "robot.toml", "table.csv"])
        outcomes.append("done" if code == 0 else "new" if made else "none")
        if code == 0:
            break
        shutil.rmtree(tmp_path / "robot", ignore_errors=True)
    assert outcomes == ["none"] * 4 + ["new", "done"]  # four files written, then the folder renamed


def test_run_writes_its_trace_and_summary_together(bot: Path, tmp_path: Path) -> None:
    outcomes = interrupt_everywhere(
        ["run", bot, "--on", "sim", "--seconds", "0.2", "-q", "--out", tmp_path / "r"],
        tmp_path / "r",
        tmp_path / "ref",
        loose=["summary.json", "trace.jsonl"],
    )
    assert outcomes == ["old"] * 2 + ["new"] * 2 + ["done"]


def test_build_leaves_the_old_firmware_or_the_new(bot: Path, tmp_path: Path) -> None:
    if not shutil.which("avr-gcc"):
        pytest.fail("avr-gcc is missing: scripts/bootstrap.sh installs it")
    # the steps either side of where the set turns new: step 12 of 22 (the build folder's sources, then the firmware)
    outcomes = interrupt_everywhere(
        ["build", bot, "--board", "uno", "--out", tmp_path / "fw"],
        tmp_path / "fw",
        tmp_path / "ref",
        points=[1, 10, 11, 12, 21, 22, 99],
    )
    assert outcomes == ["old", "old", "old", "new", "new", "new", "done"]


def test_sweep_and_tune_leave_the_old_results_or_the_new(bot: Path, tmp_path: Path) -> None:
    outcomes = interrupt_everywhere(
        [
            "sweep",
            bot,
            "--seeds",
            "0..3",
            "--seconds",
            "2",
            "--workers",
            "1",
            "--trace",
            "1,2",
            "--no-plots",
            "-q",
            "--out",
            tmp_path / "sw",
        ],
        tmp_path / "sw",
        tmp_path / "ref",
        ignore=["spec.json", "parts"],
    )  # what a resume needs
    assert outcomes.count("old") >= 3 and outcomes.count("new") >= 3
    outcomes = interrupt_everywhere(
        [
            "tune",
            bot,
            "--cells",
            "line 5 timer=800..900",
            "--budget",
            "3",
            "--seeds",
            "0..1",
            "--check-seeds",
            "5..5",
            "--seconds",
            "2",
            "--workers",
            "1",
            "--force",
            "-q",
            "--out",
            tmp_path / "tu",
        ],
        tmp_path / "tu",
        tmp_path / "ref-tune",
        loose=["report.md"],
        ignore=["evaluations.partial.json"],
        points=[2, 3, 5, 7, 9, 99],
    )  # journal writes (fewer once resumed), files, renames
    assert "old" in outcomes and "new" in outcomes and outcomes[-1] == "done"


# --- SIGKILL and the journal ------------------------------------------------------------------------


def test_a_swap_cut_by_sigkill_is_finished_by_the_next_set(tmp_path: Path) -> None:
    """The process dies between two renames: the journal lets the next set in the folder finish them."""
    folder = tmp_path / "out"
    folder.mkdir()
    for name in "abc":
        (folder / f"{name}.txt").write_text("old\n")
    script = (
        "import sys; from pathlib import Path; from tablebot.fileset import file_set; "
        "from tablebot.files import write_text\n"
        "with file_set(sys.argv[1]):\n"
        "    for name in 'abc': write_text(Path(sys.argv[1]) / f'{name}.txt', 'new\\n')\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script, str(folder)], env={**os.environ, FAULT_ENV: "5:KILL"}, timeout=60
    )
    assert done.returncode == -signal.SIGKILL
    assert [(folder / f"{n}.txt").read_text() for n in "abc"] == ["new\n", "old\n", "old\n"]  # cut mid-swap
    assert len(leftovers(folder)) == 1
    with file_set(folder):  # any later set in the folder finishes the swap first
        write_text(folder / "d.txt", "other\n")
    assert [(folder / f"{n}.txt").read_text() for n in "abcd"] == ["new\n"] * 3 + ["other\n"]
    assert not leftovers(folder)


def test_a_stage_cut_before_its_journal_is_removed_and_a_live_one_kept(tmp_path: Path) -> None:
    folder = tmp_path / "out"
    folder.mkdir()
    (folder / "a.txt").write_text("old\n")
    script = (
        "import sys, time; from pathlib import Path; from tablebot.fileset import file_set; "
        "from tablebot.files import write_text\n"
        "with file_set(sys.argv[1]):\n"
        "    write_text(Path(sys.argv[1]) / 'a.txt', 'new\\n'); print('staged', flush=True); time.sleep(60)\n"
    )
    proc = subprocess.Popen([sys.executable, "-c", script, str(folder)], stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout is not None and proc.stdout.readline() == "staged\n"
        assert recover(folder) == [] and len(leftovers(folder)) == 1  # its process lives: left alone
        proc.kill()
        proc.wait(timeout=30)
        assert len(recover(folder)) == 1  # now it is gone: no journal, so nothing was swapped
    finally:
        proc.kill()
    assert (folder / "a.txt").read_text() == "old\n" and not leftovers(folder)


# --- real signals at varied moments ---------------------------------------------------------------------


def test_real_signals_during_sim_leave_the_old_run_or_the_new(bot: Path, tmp_path: Path) -> None:
    """The issue's case: SIGINT or SIGTERM while a run draws its pictures (from the moment its finished
    trace waits in the staging folder). Ctrl-C during the run itself: tests/sim/test_sim_live.py."""
    out = tmp_path / "s"
    command = ["sim", str(bot), "--seconds", "300", "-q", "--out", str(out)]
    assert invoke(command) == 0
    (out / USER_FILE).write_text("mine\n")
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    outcomes = []
    for sig, delay in ((signal.SIGINT, 0.0), (signal.SIGTERM, 0.3)):
        before = snapshot(out)
        proc = subprocess.Popen(
            [sys.executable, "-m", "tablebot", *command],
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
        )
        deadline = time.monotonic() + 120
        while not list(out.glob(".tablebot-*/trace.jsonl")):  # the run is over: drawing
            assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
            time.sleep(0.005)
        time.sleep(delay)
        proc.send_signal(sig)
        _, err = proc.communicate(timeout=120)
        after = snapshot(out)
        assert not leftovers(out), err
        changed = {n for n in set(before) | set(after) if after.get(n) != before.get(n)}
        assert changed in (set(), {"trace.jsonl", "trajectory.png", "timeline.png"}), changed
        outcomes.append("new" if changed else "old")
        assert proc.returncode == (130 if sig == signal.SIGINT else 143), err
    assert outcomes[0] == "old"  # the second may find the pictures drawn and the swap held: then new


@pytest.mark.parametrize(
    ("cause", "code", "word"), [("KeyboardInterrupt", 130, "interrupted"), ("Terminated", 143, "terminated")]
)
def test_an_interrupt_inside_an_import_ends_as_the_interrupt(cause: str, code: int, word: str) -> None:
    """Seen with SIGTERM while matplotlib imported its compiled font module: pybind11 turned the interrupt
    into ImportError('initialization failed'), reported as an internal error, then the interpreter aborted
    on its way out."""
    script = (
        "from tablebot.cli.common import guarded\nfrom tablebot.interrupts import Terminated\n"
        f"def command():\n    raise ImportError('initialization failed') from {cause}()\n"
        "guarded(command)()\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script],
        env={**os.environ, "PYTHONPATH": str(ROOT / "src")},
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert (done.returncode, done.stderr.strip()) == (code, word)


def test_evolve_leaves_the_old_tables_or_the_new_and_resumes(tmp_path: Path) -> None:
    """Over an earlier, smaller run (--budget 3) the same search continued (--budget 6) is cut at its first
    and last file written and its first and last rename: the folder holds the earlier run's tables, check
    reports, heat map and report, or the continued run's, whole; the records a resume needs (ignored here)
    keep the work, and the same command then finishes with the tables of a run never cut."""
    bot = tmp_path / "lf"
    shutil.copytree(ROOT / "examples" / "line-follower", bot)
    out, ref = tmp_path / "ev", tmp_path / "ref"
    command = [
        "evolve",
        bot,
        "--out",
        out,
        "--batch",
        "2",
        "--seeds",
        "0..1",
        "--check-seeds",
        "10..11",
        "--seconds",
        "2",
        "--workers",
        "1",
        "-q",
    ]
    records = ["spec.json", "evaluations.jsonl", "proofs.jsonl"]  # what a resume needs, appended as work finishes
    assert invoke([*command, "--budget", "3"]) == 0
    (out / USER_FILE).write_text("mine\n")
    shutil.copytree(out, ref)
    assert invoke([str(ref) if a == out else a for a in command] + ["--budget", "6"]) == 0
    new = snapshot(ref, records)
    del new[USER_FILE]
    assert len(new) == 8 and "elites" in {name.split("/")[0] for name in new}  # 2 tables, their checks, 4 more
    outcomes = []
    for n in (1, 8, 9, 16, 99):  # 8 files written into the staging folder, then 8 renamed into place
        name = "INT" if n % 2 else "TERM"
        before = snapshot(out, records)
        code = invoke([*command, "--budget", "6"], f"{n}:{name}")
        if code == 0:
            outcomes.append("done")
            break
        assert code == (130 if name == "INT" else 143)
        outcomes.append(check_outcome(out, before, snapshot(out, records), new, loose=["report.md"]))
    assert outcomes == ["old", "old", "new", "new", "done"]
    evaluated = (out / "evaluations.jsonl").read_text().splitlines()
    assert len(evaluated) == len(set(evaluated)) == 6  # no table run twice across the cut runs
    assert (out / "evaluations.csv").read_bytes() == (ref / "evaluations.csv").read_bytes()
