"""The ``run`` command: drive a real robot (a TXT, or a TXT 4.0 running ftrobopy_server) or the simulator
in real time through the run loop, with a live view, a live trace, and outputs off on every way out."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from tablebot import registry
from tablebot.cli.app import app
from tablebot.cli.common import ROBOT_OPT, TABLE_ARG, console, err_console, guarded, open_project, out_folder
from tablebot.diagnostics import fail, severity_word
from tablebot.escape import terminal
from tablebot.i18n import N_, _, localise, ngettext

if TYPE_CHECKING:  # the engine, the loop and the robots are imported only when the command runs
    from tablebot.api.running import Connection, LiveRun
    from tablebot.loop import Sink
    from tablebot.machine import Machine


def _on_help() -> str:
    helps = [b.help for b in registry.lives()]
    return (", ".join(helps[:-1]) + ", or " + helps[-1] if len(helps) > 1 else "".join(helps)) + "."


@app.command("run")
@guarded
def run_cmd(
    table: Path = TABLE_ARG,
    on: str = typer.Option(..., "--on", help=_on_help()),
    seconds: float | None = typer.Option(None, "--seconds", min=0.01, help="Run length; without it, until Ctrl-C."),
    out: Path | None = typer.Option(
        None,
        "--out",
        help="Folder for trace.jsonl and summary.json, written as the "
        "run goes (a planned run cut short leaves trace.partial.jsonl).",
    ),
    link_timeout: float | None = typer.Option(
        None,
        "--link-timeout",
        min=0.001,
        help="Seconds without a valid reply that end the run as link_lost (default: 5 ticks).",
    ),
    behind_limit: float = typer.Option(
        0.5,
        "--behind-limit",
        min=0.0,
        help="End the run when the table's time "
        "falls this many seconds behind the wall clock within any 5 s (a stall, or "
        "a robot too slow for the tick), rather than let its timers run slow. 0: "
        "never, and run on a link too slow for the tick.",
    ),
    seed: int = typer.Option(1, "--seed", min=0, help="sim: the seed of all simulated noise (as tablebot sim)."),
    quiet: bool = typer.Option(
        False, "--quiet", "-q", help="No live view and no summary (a run that fails still says why)."
    ),
    robot: Path | None = ROBOT_OPT,
) -> None:
    """Run TABLE on a real robot (or the simulator, in real time): outputs off on Ctrl-C, SIGTERM, any error
    and at the end; a lost link ends the run with exit code 3."""
    from tablebot.api.running import live_backend

    live_backend(on)  # a wrong --on is said before the table is read
    project = open_project(table, robot)
    if out is not None:
        out_folder(out, "--out")  # before anything moves, so that a bad path fails at once
    connection = project.connect(on, link_timeout=link_timeout, behind_limit=behind_limit, seed=seed)
    for warning in connection.opened.warnings:
        err_console.print(terminal(f"{severity_word('warning')}: {localise(warning)}"))
    done = _drive(connection, seconds, out, quiet)
    if done.end.exit_code:
        raise typer.Exit(done.end.exit_code)


def _drive(connection: Connection, seconds: float | None, out: Path | None, quiet: bool) -> LiveRun:
    """The run with the live view (on a terminal, unless quiet), then what it did."""
    from tablebot.sinks.live_view import LiveView

    opened, machine = connection.opened, connection.project.machine
    sinks: list[Sink] = []
    if not quiet and err_console.is_terminal:
        sinks.append(LiveView(err_console, opened.device))
    if not quiet:
        err_console.print(
            terminal(
                _("running {table} on {where} ({device}); Ctrl-C stops it").format(
                    table=machine.table.path, where=opened.where, device=localise(opened.device)
                )
            )
        )
    done = connection.run(seconds, out, sinks)
    if not quiet:
        _report(done, machine)
    elif done.end.exit_code:  # quiet hides the live view and the summary, never why a run failed
        end = done.end
        why = f" — {localise(end.message)}" if end.message else ""
        ran = _("ran {ticks} ticks: {reason}").format(ticks=end.ticks, reason=said(end.reason))
        err_console.print(terminal(ran + why))
        for path in done.files:
            err_console.print(terminal(_("kept {path}").format(path=path)))
    return done


#: Why a run ended (tablebot.loop.EXIT_CODES' keys, which records keep as they are), in the reader's words; the
#: English words are the keys themselves, as the command always said them.
REASONS = {
    "done": N_("done"),
    "stopped": N_("stopped"),
    "error": N_("error"),
    "link_lost": N_("link_lost"),
    "watchdog": N_("watchdog"),
    "behind": N_("behind"),
    "interrupted": N_("interrupted"),
    "terminated": N_("terminated"),
}


def said(reason: str) -> str:
    return str(localise(REASONS.get(reason, reason)))


def _report(done: LiveRun, machine: Machine) -> None:
    """How the run ended on stdout; the files written on stderr."""
    end = done.end
    seconds = end.ticks * machine.table.robot.tick_s
    why = f" — {localise(end.message)}" if end.message else ""
    console.print(
        terminal(
            _("ran {ticks} ticks ({seconds:.2f} s): {reason}").format(
                ticks=end.ticks, seconds=seconds, reason=said(end.reason)
            )
            + why
        )
    )
    if end.late_ticks:
        console.print(
            ngettext(
                "{n} tick started late (worst {ms:.1f} ms)",
                "{n} ticks started late (worst {ms:.1f} ms)",
                end.late_ticks,
            ).format(n=end.late_ticks, ms=1000 * end.worst_late_s)
        )
    for path in done.files:
        err_console.print(terminal(_("wrote {path}").format(path=path)))
    sys.stdout.flush()


@app.command("upload")
@guarded
def upload_cmd(
    folder: Path = typer.Argument(
        ..., metavar="OUTDIR", help="A folder written by `tablebot export TABLE OUTDIR --to txt4`."
    ),
    to: str = typer.Option(..., "--to", help="The TXT 4.0: txt4://192.168.7.2 (USB), txt4://HOST[:PORT]."),
    key: str | None = typer.Option(
        None,
        "--key",
        help="The controller's API key (shown on the TXT 4.0, as ROBO "
        "Pro Coding asks for it). Visible to other users in the process list: prefer "
        "$TABLEBOT_TXT4_KEY, --key-file, or the prompt (asked when neither is given).",
    ),
    key_file: Path | None = typer.Option(None, "--key-file", help="A file holding the API key on one line."),
    start: bool = typer.Option(True, "--start/--no-start", help="Start the program once it is uploaded."),
) -> None:
    """Install an exported TXT 4.0 program on the controller through its REST API, and start it."""
    from tablebot.hw.txt4.upload import api_key, base_url, terminal_prompt, upload, workspace_files

    if not folder.is_dir():
        raise fail(
            folder,
            N_("is a file, not a folder") if folder.exists() else N_("no such folder"),
            N_("give the folder `tablebot export --to txt4` wrote"),
        )
    base_url(to), workspace_files(folder)  # a wrong --to or folder is said before the key is asked for
    upload(
        folder,
        to,
        api_key(key, key_file, terminal_prompt()),
        start,
        say=lambda text: console.print(terminal(str(localise(text)))),
    )
