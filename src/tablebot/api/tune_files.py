"""The files ``tune`` writes: the tuned table (the input's bytes but for the tuned cells), every evaluation,
the convergence picture and the report (:mod:`tablebot.api.tuning` runs the search)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from tablebot.fleet.plan import Plan
    from tablebot.fleet.tune import Cell, Evaluator


def tuned_path(table: Path, out: Path) -> Path:
    """``OUT/NAME.tuned.csv``: never the input itself."""
    path = out / f"{table.stem}.tuned{table.suffix or '.csv'}"
    if path.resolve() == table.resolve():
        from tablebot.diagnostics import fail
        from tablebot.i18n import N_

        raise fail(
            "--out",
            N_("the tuned table would replace its input {table}", table=str(table)),
            N_("give --out another folder"),
        )
    return path


def tuned_paths(plan: Plan, cells: Sequence[Cell], out: Path) -> dict[int, Path]:
    """Per table with a tuned cell (its index in the robot's tables, 0: the main one), ``OUT/NAME.tuned.csv``;
    a robot of one table has its tuned table even when no cell is given (it is always written)."""
    tables = plan.tables.tables if plan.tables is not None else (plan.table,)
    tuned = sorted({cell.table for cell in cells} or {0})
    return {k: tuned_path(Path(tables[k].path), out) for k in tuned}


def write_tuned(plan: Plan, cells: list[Cell], values: tuple[int, ...], path: Path, table: int = 0) -> Path:
    """Table ``table`` of the robot (0: the main one) byte for byte, but for its tuned cells (its delimiter,
    quoting and line ends kept)."""
    from tablebot.files import write_bytes
    from tablebot.formats.csv_document import CsvDocument

    mine = [(cell, value) for cell, value in zip(cells, values, strict=True) if cell.table == table]
    cells, values = [cell for cell, _ in mine], tuple(value for _, value in mine)
    source = Path((plan.tables.tables[table] if plan.tables is not None else plan.table).path)
    doc = CsvDocument.from_bytes(source.read_bytes(), str(source))
    header = [h.strip().lower() for h in doc.header_values()]
    lines = doc.record_lines()
    grid = doc.grid()
    for cell, value in zip(cells, values, strict=True):
        grid_row = next(g for g, index in enumerate(doc.row_ids) if lines[index] == cell.line)
        column = header.index(cell.column.lower())
        text = (
            str(value)
            if cell.counter is not None
            else as_written(grid[grid_row][column], value, plan.table.robot.tick_ms)
        )
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
    return old[: match.start(1)] + number + old[match.end(1) :]


def write_evaluations(evaluate: Evaluator, path: Path) -> Path:
    from tablebot.files import write_text
    from tablebot.fleet.plan import csv_text

    columns = ["evaluation", *(c.label for c in evaluate.cells), evaluate.objective]
    rows = [
        {"evaluation": k, **dict(zip(columns[1:-1], values, strict=True)), evaluate.objective: value}
        for k, (values, value) in enumerate(evaluate.history)
    ]
    return write_text(path, csv_text(columns, rows))


def convergence(evaluate: Evaluator, method: str, path: Path) -> Path:
    """The convergence picture, its text drawn as written (see tablebot.sim.pictures.draw.literal_text)."""
    from tablebot.sim.pictures.draw import literal_text
    from tablebot.sim.pictures.plots import save

    with literal_text():
        return save(convergence_figure(evaluate, method), path)


def convergence_figure(evaluate: Evaluator, method: str) -> Figure:
    """Every evaluation's objective and the best so far; for one cell also the objective against its value."""
    import numpy as np
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from tablebot.escape import picture
    from tablebot.i18n import _

    values = np.array([v for _cells, v in evaluate.history])
    one, two = len(evaluate.cells) == 1, len(evaluate.cells) == 2
    fig = Figure(figsize=(11 if one or two else 7, 4.2), dpi=120)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 2 if one or two else 1, 1)
    ax.scatter(np.arange(len(values)), values, s=8, alpha=0.4, color="#636e72", label=_("candidate"))
    ax.plot(np.minimum.accumulate(values), color="#20bf6b", linewidth=2, label=_("best so far"))
    ax.axhline(values[0], color="#e8413a", linestyle="--", linewidth=1, label=_("the table as it was"))
    ax.set_xlabel(_("evaluation"))
    ax.set_ylabel(evaluate.objective)
    ax.set_title(_("{method}: {n} candidates").format(method=method, n=len(values)), fontsize=11)
    ax.legend(fontsize=8)
    if one:
        side = fig.add_subplot(1, 2, 2)
        xs = np.array([c[0] for c, _value in evaluate.history])
        order = np.argsort(xs)
        side.plot(xs[order], values[order], color="#1f77b4", linewidth=1)
        side.axvline(evaluate.cells[0].value, color="#e8413a", linestyle="--", linewidth=1)
        side.set_xlabel(picture(_("{cell} (ticks)").format(cell=evaluate.cells[0].label)))
        side.set_ylabel(evaluate.objective)
    if two:
        side = fig.add_subplot(1, 2, 2)
        points = np.array([c for c, _value in evaluate.history])
        dots = side.scatter(points[:, 0], points[:, 1], c=values, cmap="viridis_r", s=30, marker="s")
        fig.colorbar(dots, ax=side, label=evaluate.objective)
        a, b = evaluate.cells
        best = points[int(np.argmin(values))]
        side.plot(a.value, b.value, "x", color="#e8413a", markersize=12, mew=2.5, label=_("as it was"))
        side.plot(*best, "*", color="#ffd32a", markersize=16, markeredgecolor="black", label=_("tuned"))
        side.set_xlabel(picture(a.label))
        side.set_ylabel(picture(b.label))
        side.legend(fontsize=8, loc="lower center", bbox_to_anchor=(0.5, 1.0), ncol=2, frameon=False)
    fig.tight_layout()
    return fig


def write_report(
    plan: Plan,
    check: Plan,
    evaluate: Evaluator,
    method: str,
    winner: tuple[int, ...],
    before_after: dict[str, list[float]],
    path: Path,
    wall_s: float,
    tuned: Sequence[Path],
    no_better: str = "",
) -> Path:
    """``report.md`` in the reader's language (numbers too: tablebot.i18n.number); ``no_better`` says why the
    winner is not better than the table as it was on the fresh scenarios (empty: it is better): then it is called
    the best candidate, not the tuned table, and no command to simulate it is offered."""
    from tablebot.escape import markdown_text
    from tablebot.files import write_text
    from tablebot.i18n import _, localise, number

    cells = evaluate.cells
    title = _("# Tuning {table}: {objective}").format(
        table=markdown_text(Path(plan.table.path).name), objective=evaluate.objective
    )
    lines = [
        title + (_(": no better") if no_better else ""),
        "",
        _("{method}, {n} candidates on {scenarios}, {seconds} s.").format(
            method=method, n=len(evaluate.history), scenarios=_scenarios(plan), seconds=number(wall_s, ".0f")
        ),
        "",
        "| " + " | ".join([_("cell"), _("before"), _("best candidate") if no_better else _("after")]) + " |",
        "|---|---|---|",
    ]
    lines += [f"| {markdown_text(c.label)} | {c.value} | {v} |" for c, v in zip(cells, winner, strict=True)]
    if any(c.counter is None for c in cells):
        lines += [
            "",
            _("Timers count ticks of {tick} ms (the tuned table writes each in its cell's own unit).").format(
                tick=number(plan.table.robot.tick_ms)
            ),
        ]
    lines += [
        "",
        _("Checked on {n} fresh scenarios (seeds {first}..{last}):").format(
            n=check.spec.total, first=check.spec.seeds[0], last=check.spec.seeds[-1]
        ),
        "",
        "| " + " | ".join([_("mean over the fresh scenarios"), _("before"), _("after")]) + " |",
        "|---|---|---|",
    ]
    for metric, (a, b) in before_after.items():
        mark = " " + _("(objective)") if metric == evaluate.objective else ""
        lines.append(f"| {metric}{mark} | {number(a, '.3f')} | {number(b, '.3f')} |")
    if no_better:
        names = ", ".join(markdown_text(p.name) for p in tuned)
        lines += [
            "",
            markdown_text(str(localise(no_better))),
            "",
            _(
                "{names} holds the best candidate of the tuning scenarios, for reference; it is not an improvement."
            ).format(names=names)
            if len(tuned) == 1
            else _(
                "{names} hold the best candidate of the tuning scenarios, for reference; it is not an improvement."
            ).format(names=names),
        ]
    else:
        lines += ["", _("Better than the table as it was on fresh seeds: yes."), "", *_use(plan, cells, tuned)]
    return write_text(path, "\n".join(lines) + "\n")


def _scenarios(plan: Plan) -> str:
    """``64 scenarios (16 seeds × random starts × 1 world, 60 s each)``, in the reader's language."""
    from tablebot.i18n import _, ngettext, number

    spec = plan.spec
    axes = "".join(
        _(" × random starts") if a.values == ("random",) else f" × {len(a.values)} {a.key}" for a in spec.axes
    )
    worlds = ngettext("{n} world", "{n} worlds", len(spec.worlds)).format(n=len(spec.worlds))
    return _("{total} scenarios ({seeds} seeds{axes} × {worlds}, {seconds} s each)").format(
        total=spec.total,
        seeds=len(spec.seeds),
        axes=axes,
        worlds=worlds,
        seconds=number(spec.ticks * plan.scenes[0].tick_s),
    )


def _use(plan: Plan, cells: Sequence[Cell], tuned: Sequence[Path]) -> list[str]:
    """How to run the tuned robot: ``tablebot sim`` of the tuned table, or for a robot of several tables (whose
    robot file names its table files) the tuned tables to put in place of their files."""
    from tablebot.escape import markdown_code, markdown_text
    from tablebot.i18n import _

    if plan.tables is None:
        return [
            _("Simulate the tuned table as it was tuned: {command}").format(
                command=markdown_code(sim_command(plan, tuned[0]))
            )
        ]
    sources = plan.tables.tables
    pairs = ", ".join(
        f"{markdown_text(target.name)} → {markdown_text(Path(sources[k].path).name)}"
        for k, target in tuned_paths(plan, cells, tuned[0].parent).items()
    )
    return [
        _(
            "The robot file's [tables] names its table files: put each tuned table in place of its file to run "
            "the robot as tuned ({pairs}); the other tables ran as they are."
        ).format(pairs=pairs)
    ]


def sim_command(plan: Plan, tuned: Path) -> str:
    """``tablebot sim`` of the tuned table with the robot file and world it was tuned with: beside it in
    OUT there are neither, and on its own it would get the built-in BumberBot in an empty room."""
    from tablebot.escape import shell_word

    words = ["tablebot", "sim", str(tuned)]
    for option, given in (("--robot", plan.table.robot.source), ("--world", plan.spec.worlds[0])):
        if Path(given).is_file():
            words += [option, given]
    return " ".join(shell_word(word) for word in words)
