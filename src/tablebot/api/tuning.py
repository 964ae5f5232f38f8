"""``tune`` from Python: timer values (and counter loads) that make the table do best over a fixed scenario
set, checked on fresh seeds (:class:`Tuning`); into a folder as ``tablebot tune`` writes it, resumable."""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

from tablebot.api.progress import Progress, stopped
from tablebot.i18n import N_

if TYPE_CHECKING:
    from tablebot.fleet.backends import Runner
    from tablebot.fleet.plan import Plan
    from tablebot.fleet.tune import Cell, Evaluator
    from tablebot.loading import Loaded, PathLike

METRICS = ("time_to_lamp", "time_to_light", "collisions", "lamp_distance", "missed_lamp")
JOURNAL = "evaluations.partial.json"


@dataclass(frozen=True, eq=False)
class Tuning:
    """A tuning's outcome: :attr:`winner` (a value per tuned cell, in ticks or counter counts), :attr:`history`
    (every candidate evaluated and its objective), :attr:`before_after` (each metric's mean on the fresh
    scenarios, for the table as it was and as tuned) and the :attr:`files` written. :meth:`save` writes what
    ``tablebot tune`` writes: ``NAME.tuned.csv``, ``evaluations.csv``, ``convergence.png``, ``report.md``.

    >>> import tablebot
    >>> robot = tablebot.open("examples/bumberbot")
    >>> tuned = robot.tune("line 5 timer=100..900", objective="collisions", budget=3, seeds="0..1",
    ...                    check_seeds="9..10", seconds=1)
    >>> tuned.objective, len(tuned.winner), [p.name for p in tuned.files]
    ('collisions', 1, [])
    >>> written = [p.name for p in tuned.save("out/tune")]
    >>> written
    ['table.tuned.csv', 'evaluations.csv', 'convergence.png', 'report.md']
    """

    evaluator: Evaluator
    check: Plan
    method: str
    winner: tuple[int, ...]
    before_after: dict[str, list[float]]
    wall_s: float
    files: tuple[Path, ...] = ()

    @property
    def plan(self) -> Plan:
        """The scenario set every candidate ran."""
        return self.evaluator.plan

    @property
    def cells(self) -> Sequence[Cell]:
        return self.evaluator.cells

    @property
    def objective(self) -> str:
        return self.evaluator.objective

    @property
    def history(self) -> list[tuple[tuple[int, ...], float]]:
        return self.evaluator.history

    @property
    def baseline(self) -> tuple[int, ...]:
        """The tuned cells' values in the table as it was."""
        return tuple(c.value for c in self.cells)

    @property
    def helped(self) -> bool:
        """Whether the tuned values are better than the table's own on the fresh scenarios (the objective's
        mean there is smaller): only then is the tuned table worth having. A tuning that kept the table's own
        values, or whose winner did better on the tuning scenarios alone, did not help."""
        before, after = self.before_after[self.objective]
        return self.winner != self.baseline and after < before

    def verdict(self) -> str:
        """One line: whether tuning helped, with the objective before and after on the fresh scenarios."""
        before, after = self.before_after[self.objective]
        numbers = N_(
            "{objective} {before:.3f} before, {after:.3f} after, on {n} fresh scenarios",
            objective=self.objective,
            before=before,
            after=after,
            n=self.check.spec.total,
        )
        if self.helped:
            return N_("Better than the table as it was on fresh seeds: yes ({numbers}).", numbers=numbers)
        if self.winner == self.baseline:
            return N_(
                "Better than the table as it was on fresh seeds: no: no candidate beat the table's own values "
                "({numbers}); keep the table as it is.",
                numbers=numbers,
            )
        return N_(
            "Better than the table as it was on fresh seeds: no ({numbers}): the values that did best on the "
            "tuning scenarios do not carry over; keep the table as it is, or tune on more seeds (--seeds).",
            numbers=numbers,
        )

    def report_text(self) -> str:
        """``report.md`` of the tuning written (the first of its files named so)."""
        return next(p for p in self.files if p.name == "report.md").read_text(encoding="utf-8")

    def save(self, folder: PathLike) -> list[Path]:
        """The tuned table, every evaluation, the convergence picture and the report in ``folder``, all at once
        (a tuned table of an earlier tuning there is replaced only inside a command given ``--force``)."""
        from tablebot import files
        from tablebot.fileset import file_set

        folder = files.out_folder(Path(folder), "--out")
        targets = _tuned_paths(self.plan, self.cells, folder)
        for target in targets.values():
            files.writing(target)
        with file_set(folder, remove=[JOURNAL]):
            return _outputs(self, folder, targets)


def tune(
    project: Loaded,
    cells: str,
    *,
    objective: str = "time_to_lamp",
    budget: int = 300,
    method: str = "auto",
    grid: Sequence[str] | None = None,
    seeds: str = "0..15",
    check_seeds: str = "1000..1063",
    seconds: float = 60.0,
    seed: int = 0,
    backend: str = "auto",
    scheduler: str | None = None,
    workers: int | None = None,
    out: PathLike | None = None,
    force: bool = False,
    progress: Progress | None = None,
) -> Tuning:
    """Tune the table's ``cells`` (``"line 5 timer, line 9 timer"``: file lines; a range ``"line 5
    timer=100..2000"``; counter loads ``"line 12 C1_load"``) for ``objective`` (``time_to_lamp``,
    ``time_to_light``, ``collisions``, ``lamp_distance`` or ``missed_lamp``: a mean, made smallest) over the
    scenarios of the project's worlds x ``grid`` (default ``["start=random"]``) x ``seeds``, at most
    ``budget`` candidates by ``method`` (``grid``, ``cma``, or ``auto``: grid for one or two cells), then
    measure the table before and after on ``check_seeds``. With ``out`` every evaluation is kept there as it
    is made (Ctrl-C raises :class:`~tablebot.api.progress.Stopped`; the same call resumes) and the outputs
    are written at the end, as ``tablebot tune --out`` writes them (``force``: its ``--force``)."""
    from tablebot.diagnostics import fail
    from tablebot.fleet.backends import Runner, choose
    from tablebot.fleet.plan import make_plan
    from tablebot.fleet.spec import parse_seeds
    from tablebot.fleet.tune import parse_cells

    if objective not in METRICS:
        raise fail(
            "--objective",
            N_("--objective {objective}: unknown objective", objective=objective),
            N_("use one of {choices}", choices=", ".join(METRICS)),
        )
    if method not in ("auto", "grid", "cma"):
        raise fail("--method", N_("--method {method}: unknown method", method=method), N_("use grid, cma or auto"))
    chosen, address = choose(backend, scheduler)
    plan = make_plan(
        project.path,
        project.robot_file,
        project.world_files,
        grid or ["start=random"],
        seeds,
        None,
        seconds,
        every_table=True,
    )
    metrics = measurable(plan, objective)
    check = replace(plan, spec=replace(plan.spec, seeds=parse_seeds(check_seeds, None, "--check-seeds")))
    tuned_cells = parse_cells(cells, plan.table, plan.tables)
    method = method if method != "auto" else ("grid" if len(tuned_cells) <= 2 else "cma")
    shown = progress or Progress()
    with project.writing(force):
        folder = _folder(plan, tuned_cells, Path(out)) if out is not None else None
        journal = Journal(folder / JOURNAL, plan, tuned_cells, objective) if folder is not None else None
        known = journal.load() if journal is not None else {}
        if chosen == "local":
            from tablebot.fleet.kernel import run_fleet

            shown.compiling(N_("the fleet simulator"), run_fleet)
        if known and journal is not None:
            shown.note(
                N_("resuming: {n} evaluations from {path} are not run again", n=len(known), path=str(journal.path))
            )
        started = time.perf_counter()
        with Runner(chosen, address, workers) as runner:
            tuning = _search(
                plan, check, tuned_cells, objective, method, budget, seed, metrics, runner, known, journal, shown
            )
        tuning = replace(tuning, wall_s=time.perf_counter() - started)
        return replace(tuning, files=tuple(tuning.save(folder))) if folder is not None else tuning


def _folder(plan: Plan, cells: list[Cell], out: Path) -> Path:
    """``out``, made, once the tuned tables it will hold are known to be writable there (a tuned table of an
    earlier run needs --force: said now, not after the search)."""
    from tablebot import files

    files.out_folder(out, "--out")
    for target in _tuned_paths(plan, cells, out).values():
        files.writing(target)
    return out


def _search(
    plan: Plan,
    check: Plan,
    cells: list[Cell],
    objective: str,
    method: str,
    budget: int,
    seed: int,
    metrics: tuple[str, ...],
    runner: Runner,
    known: dict[tuple[int, ...], float],
    journal: Journal | None,
    progress: Progress,
) -> Tuning:
    """The search from the table as it is, then its best candidate and the table as it was measured on the
    fresh scenarios. Ctrl-C raises Stopped, after the journal kept every evaluation made."""
    from tablebot.fleet.tune import Evaluator, best, search_cma, search_grid
    from tablebot.interrupts import INTERRUPTS

    progress.start("candidates", budget)
    try:
        evaluate = Evaluator(
            plan,
            cells,
            objective,
            runner,
            on_eval=progress.advance,
            known=known,
            on_record=journal.save if journal is not None else None,
        )
        baseline = tuple(c.value for c in cells)
        evaluate([baseline])
        if method == "grid":
            search_grid(evaluate, budget)
        else:
            search_cma(evaluate, budget, seed)
        winner, _ = best(evaluate.history)
        before_after = evaluate.measure([baseline, winner], check, metrics)
    except INTERRUPTS as exc:
        count = journal.count if journal is not None else 0
        kept = (
            N_("{count} evaluations kept in {path}", count=count, path=journal.path)
            if journal is not None and count
            else N_("no evaluation had finished")
        )
        raise stopped(kept, exc) from None
    finally:
        progress.stop()
    return Tuning(evaluate, check, method, winner, before_after, 0.0)


def _tuned_paths(plan: Plan, cells: Sequence[Cell], folder: Path) -> dict[int, Path]:
    from tablebot.api.tune_files import tuned_paths

    return tuned_paths(plan, cells, folder)


def _outputs(tuning: Tuning, folder: Path, targets: dict[int, Path]) -> list[Path]:
    from tablebot.api.tune_files import convergence, write_evaluations, write_report, write_tuned

    evaluate = tuning.evaluator
    tuned = [write_tuned(tuning.plan, list(tuning.cells), tuning.winner, target, k) for k, target in targets.items()]
    return [
        *tuned,
        write_evaluations(evaluate, folder / "evaluations.csv"),
        convergence(evaluate, tuning.method, folder / "convergence.png"),
        write_report(
            tuning.plan,
            tuning.check,
            evaluate,
            tuning.method,
            tuning.winner,
            tuning.before_after,
            folder / "report.md",
            tuning.wall_s,
            tuned,
            tuning.verdict() if not tuning.helped else "",
        ),
    ]


class Journal:
    """``OUT/evaluations.partial.json``: every evaluation so far, rewritten (atomically) after each batch,
    with what they were measured on. The same command run again takes them instead of running them."""

    def __init__(self, path: Path, plan: Plan, cells: list[Cell], objective: str) -> None:
        self.path = path
        self.tuning = {"spec": plan.spec.to_json(), "cells": [c.label for c in cells], "objective": objective}
        self.count = 0

    def load(self) -> dict[tuple[int, ...], float]:
        """The evaluations of an interrupted run of this tuning (none if there is none); another tuning's
        are refused, as sweep refuses another sweep's folder."""
        import json

        from tablebot.diagnostics import fail

        if not self.path.exists():
            return {}
        try:
            saved = json.loads(self.path.read_text(encoding="utf-8"))
            same = saved["tuning"] == self.tuning
            known = {tuple(int(v) for v in values): float(value) for values, value in saved["evaluations"]}
        except (ValueError, KeyError, TypeError):
            same, known = False, {}
        if not same:
            raise fail(
                self.path,
                N_(
                    "--out holds the evaluations of an interrupted tuning of another table, robot "
                    "file, world, scenario set, cells or objective"
                ),
                N_("give --out a new folder, or delete {name} to start over", name=self.path.name),
            )
        self.count = len(known)
        return known

    def save(self, history: list[tuple[tuple[int, ...], float]]) -> None:
        import json

        from tablebot.files import write_text

        self.count = len(history)
        evaluations = [[list(values), value] for values, value in history]
        write_text(self.path, json.dumps({"tuning": self.tuning, "evaluations": evaluations}) + "\n")


def measurable(plan: Plan, objective: str) -> tuple[str, ...]:
    """The metrics the scenarios' worlds give a meaning. Without a lamp anywhere only collisions (every
    candidate would tie on the others); the distance to the nearest lamp needs one in every world."""
    dark = [world.name for world in plan.worlds if not world.lamps]
    usable = (
        METRICS
        if not dark
        else ("collisions",)
        if len(dark) == len(plan.worlds)
        else tuple(m for m in METRICS if m != "lamp_distance")
    )
    if objective not in usable:
        from tablebot.diagnostics import fail

        options = ", ".join(f"--objective {m}" for m in usable)
        raise fail(
            "--objective",
            N_(
                "--objective {objective} needs a lamp, and {worlds} has none",
                objective=objective,
                worlds=", ".join(dark),
            ),
            N_("tune for {options}, or give every --world a [[lamp]]", options=options),
        )
    return usable
