"""``tablebot grade``: challenges graded by the fleet. A challenge (:mod:`.challenge`) names a robot, worlds,
scenarios, a score and rules; each submission (:mod:`.submissions`: a table, a folder, or a text file of share
links) is read against that robot, its rules proved, run on the fleet over the scenarios and scored
(:mod:`.run`); ``scores.csv`` and ``leaderboard.html`` are written (:mod:`.outputs`).

>>> import tablebot.grade as grade
>>> result = grade.grade("examples/challenges/find-the-lamp", ["examples/bumberbot"], "out/grade")
>>> [(e.name, e.why[:25]) for e in result.entries]
[('bumberbot', 'breaks front_bumper_stops')]
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from tablebot.grade.challenge import Challenge, load_challenge
from tablebot.grade.run import Entry
from tablebot.i18n import _

__all__ = ["Challenge", "Entry", "Grading", "grade", "load_challenge"]


@dataclass(frozen=True)
class Grading:
    """A challenge graded: the :attr:`entries` in the order given, and the files written."""

    challenge: Challenge
    entries: tuple[Entry, ...]
    files: tuple[Path, ...]


def grade(
    challenge: str | Path,
    submissions: Sequence[str | Path],
    out: str | Path,
    *,
    backend: str = "auto",
    scheduler: str | None = None,
    workers: int | None = None,
    told: Callable[[str], None] = lambda text: None,
) -> Grading:
    """Grade ``submissions`` (table files, folders holding table.csv, text files of share links) on the
    ``challenge`` (its folder or challenge.toml) on this machine's cores or a Dask cluster (``backend``,
    ``scheduler``, ``workers`` as for sweep), and write ``scores.csv``, ``leaderboard.html`` (its replays in
    it) and the linked submissions' files into ``out``, replacing an earlier grading's all at once. ``told`` hears
    what is being done."""
    from tablebot.files import out_folder, write_text
    from tablebot.fileset import file_set
    from tablebot.fleet.backends import Runner, choose
    from tablebot.grade.outputs import leaderboard_html, replay_pages, scores_csv
    from tablebot.grade.run import grade_all
    from tablebot.grade.submissions import collect

    found = load_challenge(challenge)
    chosen, address = choose(backend, scheduler)
    folder = out_folder(Path(out), "--out")
    with tempfile.TemporaryDirectory(prefix="tablebot-grade-") as tmp:
        subs = collect([Path(s) for s in submissions], Path(tmp))
        with Runner(chosen, address, workers) as runner:
            entries = grade_all(found, subs, runner, told)
        told(_("writing the leaderboard"))
        with file_set(folder, remove=_previous(folder)):
            files = [write_text(folder / "scores.csv", scores_csv(entries, found))]
            replays, packed = replay_pages(entries, found)
            files.append(write_text(folder / "leaderboard.html", leaderboard_html(entries, found, replays, packed)))
            files += _copy_linked(Path(tmp), folder)
    return Grading(found, tuple(entries), tuple(files))


def _previous(folder: Path) -> list[str]:
    """An earlier grading's linked submissions, which the new set replaces."""
    linked = folder / "submissions"
    return (
        [p.relative_to(folder).as_posix() for p in sorted(linked.rglob("*")) if p.is_file()] if linked.is_dir() else []
    )


def _copy_linked(tmp: Path, folder: Path) -> list[Path]:
    """The files the links carried, in ``out/submissions/NAME`` for the teacher to open."""
    from tablebot.files import write_bytes

    written = []
    for path in sorted((tmp / "submissions").rglob("*")) if (tmp / "submissions").is_dir() else []:
        if path.is_file():
            written.append(write_bytes(folder / path.relative_to(tmp), path.read_bytes()))
    return written
