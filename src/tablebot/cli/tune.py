"""The ``tune`` command: choose timer values (and counter loads) that make a table do best over a fixed
scenario set, then check the result on fresh seeds; writes the tuned table as a new file."""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from tablebot.cli.app import app
from tablebot.cli.common import FORCE_OPT, ROBOT_OPT, TABLE_ARG, console, err_console, guarded, out_folder
from tablebot.cli.sweep import BACKEND_OPT, SCHEDULER_OPT, WORKERS_OPT, WORLD_OPT, Bar
from tablebot.escape import plain

if TYPE_CHECKING:
    from tablebot.fleet.plan import Plan
    from tablebot.fleet.tune import Cell, Evaluator

METRICS = ("time_to_lamp", "time_to_light", "collisions", "lamp_distance", "missed_lamp")


@app.command("tune")
@guarded
def tune_cmd(
    table: Path = TABLE_ARG,
    cells: str = typer.Option(..., "--cells", help='Cells to tune: "line 5 timer, line 9 timer" (file lines; '
                              'a range: "line 5 timer=100..2000"; counter loads: "line 12 C1_load").'),
    objective: str = typer.Option("time_to_lamp", "--objective", help="What to make smallest: time_to_lamp, "
                                  "time_to_light, collisions, lamp_distance or missed_lamp (means over the "
                                  "scenarios)."),
    budget: int = typer.Option(300, "--budget", min=1, help="Most candidates to evaluate."),
    method: str = typer.Option("auto", "--method", help="grid, cma (CMA-ES with integer margin) or auto: "
                               "grid for one or two cells, else cma."),
    world: list[Path] | None = WORLD_OPT,
    grid: list[str] | None = typer.Option(None, "--grid", help='Scenario grid as in sweep (default: '
                                          '"start=random").'),
    seeds: str = typer.Option("0..15", "--seeds", help="Seeds of the scenario set every candidate runs."),
    check_seeds: str = typer.Option("1000..1063", "--check-seeds", help="Fresh seeds for the before/after check."),
    seconds: float = typer.Option(60.0, "--seconds", min=0.01, max=3600, help="Simulated time of each run."),
    seed: int = typer.Option(0, "--seed", min=0, help="Seed of CMA-ES itself."),
    backend: str = BACKEND_OPT,
    scheduler: str | None = SCHEDULER_OPT,
    workers: int | None = WORKERS_OPT,
    out: Path = typer.Option(Path("out/tune"), "--out", help="Folder for the tuned table, report.md and "
                             "convergence.png."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bar and no report on the terminal."),
    robot: Path | None = ROBOT_OPT,
    force: bool = FORCE_OPT,
) -> None:
    """Tune TABLE's timers (and counter loads) for an objective over a fixed scenario set (every candidate
    runs the same seeds, starts and batteries), check the best on fresh seeds, and write it as a new table.
    Ctrl-C (or SIGTERM) keeps every evaluation made; the same command again resumes."""
    from tablebot import files
    from tablebot.diagnostics import fail
    from tablebot.fileset import current, file_set
    from tablebot.fleet.backends import Runner, choose
    from tablebot.fleet.plan import make_plan
    from tablebot.fleet.spec import parse_seeds
    from tablebot.fleet.tune import Evaluator, best, parse_cells, search_cma, search_grid
    from tablebot.interrupts import INTERRUPTS

    if objective not in METRICS:
        raise fail("--objective", f"--objective {objective}: unknown objective", f"use one of {', '.join(METRICS)}")
    if method not in ("auto", "grid", "cma"):
        raise fail("--method", f"--method {method}: unknown method", "use grid, cma or auto")
    chosen, address = choose(backend, scheduler)
    plan = make_plan(table, robot, world or [], grid or ["start=random"], seeds, None, seconds)
    metrics = measurable(plan, objective)
    check = replace(plan, spec=replace(plan.spec, seeds=parse_seeds(check_seeds, None, "--check-seeds")))
    tuned_cells = parse_cells(cells, plan.table)
    out_folder(out, "--out")
    target = tuned_path(Path(plan.table.path), out)
    files.writing(target)  # a tuned table of an earlier run needs --force: say so now, not after the search
    method = method if method != "auto" else ("grid" if len(tuned_cells) <= 2 else "cma")
    journal = Journal(out / JOURNAL, plan, tuned_cells, objective)
    known = journal.load()
    if chosen == "local":
        from tablebot.fleet.kernel import run_fleet
        from tablebot.jit import say_compiling

        say_compiling("the fleet simulator", run_fleet)
    if known and not quiet:
        err_console.print(f"resuming: {len(known)} evaluations from {plain(str(journal.path))} are not run again",
                          markup=False)
    started = time.perf_counter()
    try:
        with Runner(chosen, address, workers) as runner, Bar("candidates", budget, quiet) as bar:
            evaluate = Evaluator(plan, tuned_cells, objective, runner, on_eval=bar.advance, known=known,
                                 on_record=journal.save)
            baseline = tuple(c.value for c in tuned_cells)
            evaluate([baseline])
            if method == "grid":
                search_grid(evaluate, budget)
            else:
                search_cma(evaluate, budget, seed)
            winner, _ = best(evaluate.history)
            before_after = evaluate.measure([baseline, winner], check, metrics)
    except INTERRUPTS as exc:
        journal.stopped(exc)
    with file_set(out, remove=[JOURNAL]):  # the tuned table, evaluations, picture and report: all at once
        written = [write_tuned(plan, tuned_cells, winner, target),
                   write_evaluations(evaluate, out / "evaluations.csv"),
                   convergence(evaluate, method, out / "convergence.png"),
                   write_report(plan, check, evaluate, method, winner, before_after, out / "report.md",
                                time.perf_counter() - started, target)]
        text = current(out / "report.md").read_text(encoding="utf-8")
    if not quiet:
        for line in text.splitlines():  # the report names the table and its cells: user text
            console.print(plain(line), markup=False)
        for path in written:
            err_console.print(f"wrote {plain(str(path))}", markup=False)


JOURNAL = "evaluations.partial.json"


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
            raise fail(self.path, "--out holds the evaluations of an interrupted tuning of another table, robot "
                       "file, world, scenario set, cells or objective", f"give --out a new folder, or delete "
                       f"{self.path.name} to start over")
        self.count = len(known)
        return known

    def save(self, history: list[tuple[tuple[int, ...], float]]) -> None:
        import json

        from tablebot.files import write_text

        self.count = len(history)
        evaluations = [[list(values), value] for values, value in history]
        write_text(self.path, json.dumps({"tuning": self.tuning, "evaluations": evaluations}) + "\n")

    def stopped(self, why: BaseException) -> None:
        """Ctrl-C or SIGTERM: say what was kept, then exit 130 (143)."""
        from tablebot.interrupts import Terminated

        word = "terminated" if isinstance(why, Terminated) else "interrupted"
        kept = f"{self.count} evaluations kept in {plain(str(self.path))}" if self.count else \
            "no evaluation had finished"
        err_console.print(f"{word}: {kept}; run the same command again to resume", markup=False)
        raise typer.Exit(143 if isinstance(why, Terminated) else 130) from None


def measurable(plan: Plan, objective: str) -> tuple[str, ...]:
    """The metrics the scenarios' worlds give a meaning. Without a lamp anywhere only collisions (every
    candidate would tie on the others); the distance to the nearest lamp needs one in every world."""
    dark = [world.name for world in plan.worlds if not world.lamps]
    usable = METRICS if not dark else ("collisions",) if len(dark) == len(plan.worlds) else \
        tuple(m for m in METRICS if m != "lamp_distance")
    if objective not in usable:
        from tablebot.diagnostics import fail

        raise fail("--objective", f"--objective {objective} needs a lamp, and {', '.join(dark)} has none",
                   f"tune for {' or '.join(f'--objective {m}' for m in usable)}, or give every --world a [[lamp]]")
    return usable


def tuned_path(table: Path, out: Path) -> Path:
    """``OUT/NAME.tuned.csv``: never the input itself."""
    path = out / f"{table.stem}.tuned{table.suffix or '.csv'}"
    if path.resolve() == table.resolve():
        from tablebot.diagnostics import fail
        raise fail("--out", f"the tuned table would replace its input {table}", "give --out another folder")
    return path


def write_tuned(plan: Plan, cells: list[Cell], values: tuple[int, ...], path: Path) -> Path:
    """The input table byte for byte, but for the tuned cells (its delimiter, quoting and line ends kept)."""
    from tablebot.files import write_bytes
    from tablebot.web.document import CsvDocument

    source = Path(plan.table.path)
    doc = CsvDocument.from_bytes(source.read_bytes(), str(source))
    header = [h.strip().lower() for h in doc.header_values()]
    lines = doc.record_lines()
    grid = doc.grid()
    for cell, value in zip(cells, values, strict=True):
        grid_row = next(g for g, index in enumerate(doc.row_ids) if lines[index] == cell.line)
        column = header.index(cell.column.lower())
        text = str(value) if cell.counter is not None else \
            as_written(grid[grid_row][column], value, plan.table.robot.tick_ms)
        doc.set_cell(grid_row, column, text)
    return write_bytes(path, doc.to_bytes())


def as_written(old: str, ticks: int, tick_ms: int) -> str:
    """A tuned timer in the unit its cell was written in: ``300ms`` tuned to 45 ticks of 10 ms is
    ``450ms`` (not ``45``, which reads as a shorter time), ``0.5 s`` stays seconds, a bare number counts ticks."""
    from decimal import Decimal

    from tablebot.durations import DURATION_RE, MS_PER

    match = DURATION_RE.match(old)
    if match is None:
        return str(ticks)
    unit = (match[2] or "").lower()
    number = format(Decimal(ticks * tick_ms) / MS_PER[unit], "f") if unit in MS_PER else str(ticks)
    return old[:match.start(1)] + number + old[match.end(1):]


def write_evaluations(evaluate: Evaluator, path: Path) -> Path:
    from tablebot.files import write_text
    from tablebot.fleet.plan import csv_text

    columns = ["evaluation", *(c.label for c in evaluate.cells), evaluate.objective]
    rows = [{"evaluation": k, **dict(zip(columns[1:-1], values, strict=True)), evaluate.objective: value}
            for k, (values, value) in enumerate(evaluate.history)]
    return write_text(path, csv_text(columns, rows))


def convergence(evaluate: Evaluator, method: str, path: Path) -> Path:
    """The convergence picture, its text drawn as written (see tablebot.sim.draw.literal_text)."""
    from tablebot.sim.draw import literal_text

    with literal_text():
        return _convergence(evaluate, method, path)


def _convergence(evaluate: Evaluator, method: str, path: Path) -> Path:
    """Every evaluation's objective and the best so far; for one cell also the objective against its value."""
    import numpy as np
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from tablebot.escape import picture
    from tablebot.sim.plots import save

    values = np.array([v for _, v in evaluate.history])
    one, two = len(evaluate.cells) == 1, len(evaluate.cells) == 2
    fig = Figure(figsize=(11 if one or two else 7, 4.2), dpi=120)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 2 if one or two else 1, 1)
    ax.scatter(np.arange(len(values)), values, s=8, alpha=0.4, color="#636e72", label="candidate")
    ax.plot(np.minimum.accumulate(values), color="#20bf6b", linewidth=2, label="best so far")
    ax.axhline(values[0], color="#e8413a", linestyle="--", linewidth=1, label="the table as it was")
    ax.set_xlabel("evaluation")
    ax.set_ylabel(evaluate.objective)
    ax.set_title(f"{method}: {len(values)} candidates", fontsize=11)
    ax.legend(fontsize=8)
    if one:
        side = fig.add_subplot(1, 2, 2)
        xs = np.array([c[0] for c, _ in evaluate.history])
        order = np.argsort(xs)
        side.plot(xs[order], values[order], color="#1f77b4", linewidth=1)
        side.axvline(evaluate.cells[0].value, color="#e8413a", linestyle="--", linewidth=1)
        side.set_xlabel(picture(f"{evaluate.cells[0].label} (ticks)"))
        side.set_ylabel(evaluate.objective)
    if two:
        side = fig.add_subplot(1, 2, 2)
        points = np.array([c for c, _ in evaluate.history])
        dots = side.scatter(points[:, 0], points[:, 1], c=values, cmap="viridis_r", s=30, marker="s")
        fig.colorbar(dots, ax=side, label=evaluate.objective)
        a, b = evaluate.cells
        best = points[int(np.argmin(values))]
        side.plot(a.value, b.value, "x", color="#e8413a", markersize=12, mew=2.5, label="as it was")
        side.plot(*best, "*", color="#ffd32a", markersize=16, markeredgecolor="black", label="tuned")
        side.set_xlabel(picture(a.label))
        side.set_ylabel(picture(b.label))
        side.legend(fontsize=8, loc="lower center", bbox_to_anchor=(0.5, 1.0), ncol=2, frameon=False)
    fig.tight_layout()
    return save(fig, path)


def write_report(plan: Plan, check: Plan, evaluate: Evaluator, method: str, winner: tuple[int, ...],
                 before_after: dict[str, list[float]], path: Path, wall_s: float, tuned: Path) -> Path:
    from tablebot.files import write_text

    spec, cells = plan.spec, evaluate.cells
    seconds = spec.ticks * plan.scenes[0].tick_s
    axes = "".join(" × random starts" if a.values == ("random",) else f" × {len(a.values)} {a.key}"
                   for a in spec.axes)
    scenario = (f"{spec.total} scenarios ({len(spec.seeds)} seeds{axes} × {len(spec.worlds)} world(s), "
                f"{seconds:g} s each)")
    lines = [f"# Tuning {Path(plan.table.path).name}: {evaluate.objective}", "",
             f"{method}, {len(evaluate.history)} candidates on {scenario}, {wall_s:.0f} s.", "",
             "| cell | before | after |", "|---|---|---|"]
    lines += [f"| {c.label} | {c.value} | {v} |" for c, v in zip(cells, winner, strict=True)]
    if any(c.counter is None for c in cells):
        lines += ["", f"Timers count ticks of {plan.table.robot.tick_ms} ms (the tuned table writes each in its "
                  "cell's own unit)."]
    lines += ["", f"Checked on {check.spec.total} fresh scenarios (seeds {check.spec.seeds[0]}.."
              f"{check.spec.seeds[-1]}):", "", "| mean over the fresh scenarios | before | after |", "|---|---|---|"]
    for metric, (a, b) in before_after.items():
        lines.append(f"| {metric}{' (objective)' if metric == evaluate.objective else ''} | {a:.3f} | {b:.3f} |")
    lines += ["", f"Simulate the tuned table as it was tuned: `{sim_command(plan, tuned)}`"]
    return write_text(path, "\n".join(lines) + "\n")


def sim_command(plan: Plan, tuned: Path) -> str:
    """``tablebot sim`` of the tuned table with the robot file and world it was tuned with: beside it in
    OUT there are neither, and on its own it would get the built-in BumberBot in an empty room."""
    from tablebot.escape import shell_word

    words = ["tablebot", "sim", str(tuned)]
    for option, given in (("--robot", plan.table.robot.source), ("--world", plan.spec.worlds[0])):
        if Path(given).is_file():
            words += [option, given]
    return " ".join(shell_word(word) for word in words)
