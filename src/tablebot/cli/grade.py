"""The ``grade`` command: every submission to a challenge checked against its robot, its rules proved, run on
the fleet over the challenge's scenarios and scored (:func:`tablebot.grade.grade`); the leaderboard printed
and written."""

from __future__ import annotations

from pathlib import Path

import typer

from tablebot.cli.app import app
from tablebot.cli.common import console, err_console, guarded
from tablebot.cli.sweep import BACKEND_OPT, SCHEDULER_OPT, WORKERS_OPT
from tablebot.escape import plain
from tablebot.i18n import _, localise


@app.command("grade")
@guarded
def grade_cmd(
    challenge: Path = typer.Argument(..., metavar="CHALLENGE", help="A challenge folder (its challenge.toml)."),
    submissions: list[Path] = typer.Argument(
        ...,
        metavar="SUBMISSION...",
        help="Tables, folders holding table.csv, or text files of share links (one a line).",
    ),
    out: Path = typer.Option(
        Path("out/grade"), "--out", help="Folder for scores.csv, leaderboard.html and the replays."
    ),
    backend: str = BACKEND_OPT,
    scheduler: str | None = SCHEDULER_OPT,
    workers: int | None = WORKERS_OPT,
    quiet: bool = typer.Option(False, "--quiet", "-q", help="Print nothing but errors."),
) -> None:
    """Grade SUBMISSIONs on CHALLENGE: each table is read with the challenge's robot, its rules are proved (a
    table that breaks one scores nothing, and the leaderboard says how it breaks it), and the others run on the
    same scenarios and are ranked by the challenge's score. A broken submission is listed with its error.
    Writes scores.csv (the same bytes on any machine) and leaderboard.html (opens offline)."""
    from tablebot.grade import grade
    from tablebot.grade.outputs import scores_csv

    def told(text: str) -> None:
        if not quiet:
            err_console.print(plain(str(localise(text))), markup=False)

    graded = grade(challenge, submissions, out, backend=backend, scheduler=scheduler, workers=workers, told=told)
    if not quiet:
        for line in scores_csv(list(graded.entries), graded.challenge).splitlines():  # pupils' names: user text
            console.print(plain(line), markup=False)
        err_console.print(
            _("wrote {scores} and {board}").format(
                scores=plain(str(Path(out) / "scores.csv")), board=plain(str(Path(out) / "leaderboard.html"))
            ),
            markup=False,
        )
