"""The ``run`` command: drive a real robot (a TXT, or a TXT 4.0 running ftrobopy_server) or the simulator
in real time through the run loop, with a live view, a live trace, and outputs off on every way out."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from tablebot import registry
from tablebot.cli.app import app
from tablebot.cli.common import ROBOT_OPT, TABLE_ARG, console, err_console, guarded, load, out_folder
from tablebot.diagnostics import fail
from tablebot.escape import terminal

if TYPE_CHECKING:  # the engine, the loop and the robots are imported only when the command runs
    from tablebot.loop import RobotIO, RunEnd, Sink
    from tablebot.machine import Machine
    from tablebot.sinks.run_trace import RunTrace

def _address_hint() -> str:
    """Every address form of every live back-end: ``write --on txt://HOST:PORT, ..., sim or sim:WORLD.toml``."""
    forms = [form for backend in registry.backends("live") for form in backend.addresses]
    return "write --on " + (", ".join(forms[:-1]) + " or " + forms[-1] if len(forms) > 1 else "".join(forms))


TARGET_HINT = _address_hint()


def live_backend(text: str) -> registry.Backend:
    """The live back-end ``--on`` names; anything else is a located error."""
    backend = registry.live_for(text)
    if backend is None:
        raise fail("--on", f"unknown target {text!r}", TARGET_HINT)
    return backend


def _on_help() -> str:
    helps = [b.help for b in registry.backends("live")]
    return (", ".join(helps[:-1]) + ", or " + helps[-1] if len(helps) > 1 else "".join(helps)) + "."


@app.command("run")
@guarded
def run_cmd(
    table: Path = TABLE_ARG,
    on: str = typer.Option(..., "--on", help=_on_help()),
    seconds: float | None = typer.Option(None, "--seconds", min=0.01, help="Run length; without it, until Ctrl-C."),
    out: Path | None = typer.Option(None, "--out", help="Folder for trace.jsonl and summary.json, written as the "
                                    "run goes (a planned run cut short leaves trace.partial.jsonl)."),
    link_timeout: float | None = typer.Option(None, "--link-timeout", min=0.001, help="Seconds without a valid "
                                              "reply that end the run as link_lost (default: 5 ticks)."),
    behind_limit: float = typer.Option(0.5, "--behind-limit", min=0.0, help="End the run when the table's time "
                                       "falls this many seconds behind the wall clock within any 5 s (a stall, or "
                                       "a robot too slow for the tick), rather than let its timers run slow. 0: "
                                       "never, and run on a link too slow for the tick."),
    seed: int = typer.Option(1, "--seed", min=0, help="sim: the seed of all simulated noise (as tablebot sim)."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No live view and no summary (a run that fails still "
                               "says why)."),
    robot: Path | None = ROBOT_OPT,
) -> None:
    """Run TABLE on a real robot (or the simulator, in real time): outputs off on Ctrl-C, SIGTERM, any error
    and at the end; a lost link ends the run with exit code 3."""
    backend = live_backend(on)
    parsed, machine = load(table, robot)
    tick_s = parsed.robot.tick_s
    ticks = None if seconds is None else max(1, round(seconds / tick_s))
    if out is not None:
        out_folder(out, "--out")  # before anything moves, so that a bad path fails at once
    assert backend.open is not None
    opened = backend.open(machine, on, {"link_timeout_s": link_timeout, "seed": seed, "hint": TARGET_HINT,
                                        "behind_limit_s": behind_limit})
    for warning in opened.warnings:
        err_console.print(terminal(f"warning: {warning}"))
    end = _drive(machine, opened.robot, opened.where, opened.device, ticks, out, behind_limit or None, quiet)
    if end.exit_code:
        raise typer.Exit(end.exit_code)


def _drive(machine: Machine, bot: RobotIO, target: str, device: str, ticks: int | None, out: Path | None,
           behind_limit_s: float | None, quiet: bool) -> RunEnd:
    """The loop with its sinks: the live view first (so it always ends first and restores the terminal).
    A TXT paces exchanges at 10 ms but ftrobopy_server on a TXT 4.0 answers at once and the simulator
    never waits, so the clock paces ticks too (it only sleeps when a tick is early; see loop.RealTimeClock)."""
    from tablebot.engine import Engine
    from tablebot.loop import RealTimeClock, run
    from tablebot.sinks.live_view import LiveView
    from tablebot.sinks.run_trace import RunTrace

    sinks: list[Sink] = []
    if not quiet and err_console.is_terminal:
        sinks.append(LiveView(err_console, device))
    trace = RunTrace(out) if out is not None else None
    if trace is not None:
        sinks.append(trace)
    if not quiet:
        err_console.print(terminal(f"running {machine.table.path} on {target} ({device}); Ctrl-C stops it"))
    switch = sys.getswitchinterval()
    sys.setswitchinterval(0.001)  # the live view's thread hands the interpreter back within 1 ms, not 5
    try:
        end = run(Engine(machine), bot, clock=RealTimeClock(machine.table.robot.tick_s), sinks=sinks,
                  ticks=ticks, target=target, behind_limit_s=behind_limit_s)
    finally:
        sys.setswitchinterval(switch)
    if not quiet:
        _report(end, machine, trace)
    elif end.exit_code:  # quiet hides the live view and the summary, never why a run failed
        why = f" — {end.message}" if end.message else ""
        err_console.print(terminal(f"ran {end.ticks} ticks: {end.reason}{why}"))
        for path in trace.files if trace is not None else []:
            err_console.print(terminal(f"kept {path}"))
    return end


def _report(end: RunEnd, machine: Machine, trace: RunTrace | None) -> None:
    """How the run ended on stdout; the files written on stderr."""
    seconds = end.ticks * machine.table.robot.tick_s
    why = f" — {end.message}" if end.message else ""
    console.print(terminal(f"ran {end.ticks} ticks ({seconds:.2f} s): {end.reason}{why}"))
    if end.late_ticks:
        ticks = "tick" if end.late_ticks == 1 else "ticks"
        console.print(f"{end.late_ticks} {ticks} started late (worst {1000 * end.worst_late_s:.1f} ms)")
    for path in trace.files if trace is not None else []:
        err_console.print(terminal(f"wrote {path}"))
    sys.stdout.flush()


@app.command("upload")
@guarded
def upload_cmd(
    folder: Path = typer.Argument(..., metavar="OUTDIR",
                                 help="A folder written by `tablebot export TABLE OUTDIR --to txt4`."),
    to: str = typer.Option(..., "--to", help="The TXT 4.0: txt4://192.168.7.2 (USB), txt4://HOST[:PORT]."),
    key: str | None = typer.Option(None, "--key", help="The controller's API key (shown on the TXT 4.0, as ROBO "
                                   "Pro Coding asks for it). Visible to other users in the process list: prefer "
                                   "$TABLEBOT_TXT4_KEY, --key-file, or the prompt (asked when neither is given)."),
    key_file: Path | None = typer.Option(None, "--key-file", help="A file holding the API key on one line."),
    start: bool = typer.Option(True, "--start/--no-start", help="Start the program once it is uploaded."),
) -> None:
    """Install an exported TXT 4.0 program on the controller through its REST API, and start it."""
    from tablebot.hw.txt4.upload import api_key, base_url, terminal_prompt, upload, workspace_files

    if not folder.is_dir():
        raise fail(folder, "is a file, not a folder" if folder.exists() else "no such folder",
                   "give the folder `tablebot export --to txt4` wrote")
    base_url(to), workspace_files(folder)  # a wrong --to or folder is said before the key is asked for
    upload(folder, to, api_key(key, key_file, terminal_prompt()), start, say=lambda text: console.print(terminal(text)))
