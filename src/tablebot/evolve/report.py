"""What a person gets from a run: the best tables and the archive's elites written as tables (with
descriptions that say what evolution changed, and the robot's state names), each with its ``check``
report; the archive's heat map; and the change of the objective a table made, for ``report.md``
(:mod:`tablebot.evolve.report_md` writes it, :mod:`tablebot.evolve.commands` the commands it offers).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tablebot.analysis.check import CheckReport
from tablebot.analysis.diagram import action, condition
from tablebot.evolve.commands import Replay as Replay  # its home before evolve/commands.py
from tablebot.evolve.measures import Measure, fitness
from tablebot.evolve.proofs import Prover
from tablebot.evolve.space import Candidate, Gene, renumbered, to_table
from tablebot.files import write_text
from tablebot.formats.table_write import format_table
from tablebot.i18n import _, localise, ngettext, number
from tablebot.machine import compile_table
from tablebot.table import Row, Table


@dataclass(frozen=True)
class Written:
    """A table written by the run: what it is, where, and whether every property holds in it."""

    label: str
    key: str
    path: Path
    check: Path
    holds: bool


# --- tables ------------------------------------------------------------------------------------------


def describe(gene: Gene, base: Table) -> str:
    """A row's description: the starting row's own words, with what evolution changed said after them;
    an added row says what it needs and does."""
    table = base
    original = next(
        (row for row in base.rows if row.line == gene.origin and row.state == gene.state),  # a group
        next((row for row in base.rows if row.line == gene.origin), None),
    )  # row is one per state
    if original is None:
        if gene.description and gene.note.startswith("guard"):
            return str(localise(gene.description))
        what = action(table, _row(gene))
        timer = f", {what.timer}" if what.timer else ""
        goes = f" -> {table.state_title(gene.next)}"
        return _("{when}: {action} (added: {note})").format(
            when=condition(table, [gene.events]),
            action=f"{what.text}{timer}{goes}",
            note=localise(gene.note) if gene.note else _("new row"),
        )
    changes = []
    for name, old, new in zip(table.robot.motors, original.motors, gene.motors, strict=True):
        if old != new:
            changes.append(f"{name} {_speed(old)}->{_speed(new)}")
    for name, old_level, new_level in zip(table.robot.lamps, original.lamps, gene.lamps, strict=True):
        if old_level != new_level:
            changes.append(f"{name} {_level(old_level)}->{_level(new_level)}")
    if original.timer != gene.timer:
        changes.append(_("timer {old}->{new}").format(old=original.timer, new=gene.timer))
    if original.next != gene.next:
        changes.append(_("next {old}->{new}").format(old=original.next, new=gene.next))
    if original.state != gene.state:
        changes.append(_("moved from state {state}").format(state=original.state))
    text = original.description or _("line {line}").format(line=original.line)
    return (
        _("{text} (evolved: {changes})").format(text=text, changes=", ".join(changes))
        if changes
        else original.description
    )


def _speed(value: int | None) -> str:
    return _("keep") if value is None else f"{value:+d}"


def _level(value: int | None) -> str:
    return _("keep") if value is None else str(value)


def _row(gene: Gene) -> Row:
    return Row(
        0, 0, gene.description, gene.state, gene.events, gene.motors, gene.timer, gene.next, gene.counters, gene.lamps
    )


def pruned(candidate: Candidate, base: Table) -> Candidate:
    """Without the rows that can fire in no situation at all (an earlier row of their state always wins):
    the same machine (the same canonical form), a shorter table to read."""
    machine = compile_table(to_table(candidate, base))
    fires = set(machine.flat or range(len(candidate)))
    return tuple(gene for index, gene in enumerate(candidate) if index in fires)


def as_table(candidate: Candidate, base: Table, path: Path) -> Table:
    """The candidate as the table that will be written to ``path`` (rows on their new lines; rows that
    can never fire left out)."""
    candidate = pruned(candidate, base)
    described = tuple(
        Gene(g.state, g.events, g.motors, g.timer, g.next, describe(g, base), g.counters, g.lamps, g.origin, g.note)
        for g in candidate
    )
    return renumbered(to_table(described, base, str(path)))


def write_table(table: Table, label: str, key: str, checked: tuple[str, bool]) -> Written:
    """The table (:func:`as_table`) in the document's layout (``formats.table_write``) at its path, and
    beside it its check report (``checked``: its text, and whether every property holds)."""
    path = Path(table.path)
    write_text(path, format_table(table))
    check = path.with_suffix(".check.txt")
    write_text(check, checked[0])
    return Written(label, key, path, check, checked[1])


_FINDING_WORDS = {"error": lambda: _("error"), "warning": lambda: _("warning"), "info": lambda: _("info")}


def check_text(report: CheckReport, prover: Prover) -> str:
    """``tablebot check``'s report in plain text, in the language in use: every property and every finding, by
    file line."""
    table, machine = report.machine.table, report.machine
    sources = ", ".join(str(f) for f in prover.files) or _("none")
    head = _("{file}: {rows} rows, {states} states, ").format(
        file=Path(table.path).name, rows=len(table.rows), states=len(machine.states)
    )
    whole = prover.whole
    if whole is not None and report.tables is not None:  # one table of several: proved with the others
        mine = report.tables.machines[whole.index]
        head = _(
            "{file} (table {name}; unchanged beside it: {others}): {rows} rows, {states} states; the tables together: "
        ).format(
            file=Path(mine.table.path).name,
            name=whole.name,
            others=", ".join(whole.others),
            rows=len(mine.table.rows),
            states=len(mine.states),
        )
    lines = [
        head + _("{situations} situations explored").format(situations=report.situations),
        "",
        _("properties (the robot file's and {sources}):").format(sources=sources),
    ]
    marks = {"holds": _("holds"), "violated": _("VIOLATED"), "unknown": _("unknown")}
    width = max(len(mark) for mark in marks.values())
    for result in report.results:
        lines.append(f"  {marks[result.status]:<{width}} {result.prop.name}: {result.prop.text}")
        lines.append(" " * (width + 3) + str(localise(result.prop.claim())))
    lines += ["", _("findings:")]
    lines += [
        f"  {Path(f.path or table.path).name}:{','.join(map(str, f.lines)) or '-'}: "
        f"{_FINDING_WORDS[f.severity]()}: {localise(f.message)}"
        for f in report.findings
    ] or ["  " + _("none")]
    counts = report.counts()
    lines += [
        "",
        ", ".join(
            [
                ngettext("{n} error", "{n} errors", counts["error"]).format(n=counts["error"]),
                ngettext("{n} warning", "{n} warnings", counts["warning"]).format(n=counts["warning"]),
                ngettext("{n} note", "{n} notes", counts["info"]).format(n=counts["info"]),
            ]
        ),
    ]
    return "\n".join(lines) + "\n"


# --- the archive's picture ------------------------------------------------------------------------------


def heat_map(
    archive: object,
    descriptors: Sequence,
    objective: Measure,
    history: Sequence[dict[str, float]],
    start: tuple[float, ...] | None,
    path: Path,
    start_label: str | None = None,
) -> Path:
    from tablebot.sim.pictures.draw import literal_text

    with literal_text():
        return _heat_map(
            archive,
            descriptors,
            objective,
            history,
            start,
            path,
            _("the starting table") if start_label is None else start_label,
        )


def _heat_map(
    archive: object,
    descriptors: Sequence,
    objective: Measure,
    history: Sequence[dict[str, float]],
    start: tuple[float, ...] | None,
    path: Path,
    start_label: str,
) -> Path:
    """Left: each cell's elite coloured by its objective (the start marked); right: the best objective
    and the cells filled as the evaluations went on."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from tablebot.sim.pictures.plots import save

    data = archive.data(["objective", "index"])  # type: ignore[attr-defined]
    cells = archive.int_to_grid_index(data["index"]) if len(data["index"]) else np.zeros((0, len(descriptors)))  # type: ignore[attr-defined]
    values = np.array([fitness(objective, v) for v in data["objective"]])
    fig = Figure(figsize=(12, 4.8), dpi=110)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 2, 1)
    cmap = "viridis_r" if objective.better == "low" else "viridis"
    first = descriptors[0]
    if len(descriptors) == 2:
        second = descriptors[1]
        grid = np.full((second.cells, first.cells), np.nan)
        for (i, j), v in zip(cells, values, strict=True):
            grid[j, i] = v
        image = ax.imshow(
            grid, origin="lower", cmap=cmap, aspect="auto", extent=(first.low, first.high, second.low, second.high)
        )
        fig.colorbar(image, ax=ax, label=_better(objective))
        ax.set_ylabel(f"{second.name}")
        if start is not None:
            ax.plot(
                np.clip(start[0], first.low, first.high),
                np.clip(start[1], second.low, second.high),
                "x",
                color="#e8413a",
                markersize=12,
                mew=2.5,
                label=start_label,
                clip_on=False,
            )  # on the grid's edge (a value beyond the range) it shows whole
            ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13), frameon=False)  # off the cells
    else:
        width = (first.high - first.low) / first.cells
        lefts = [first.low + c[0] * width for c in cells]
        ax.bar(lefts, values, width=width * 0.9, align="edge", color="#20bf6b")
        ax.set_xlim(first.low, first.high)  # the whole range, empty cells too
        ax.set_ylabel(_better(objective))
        if start is not None:
            ax.axvline(np.clip(start[0], first.low, first.high), color="#e8413a", linestyle="--", label=start_label)
            ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13), frameon=False)
    ax.set_xlabel(first.name)
    ax.set_title(
        _("archive: {elites} elites in {cells} cells").format(
            elites=len(values), cells=int(np.prod([d.cells for d in descriptors]))
        ),
        fontsize=11,
    )
    side = fig.add_subplot(1, 2, 2)
    xs = [h["evaluated"] for h in history]
    side.plot(
        xs,
        [h["best"] for h in history],
        color="#20bf6b",
        linewidth=2,
        drawstyle="steps-post",
        label=_("best {measure}").format(measure=objective.name),
    )
    side.set_xlabel(_("tables evaluated on the fleet"))
    side.set_ylabel(_("best {measure}").format(measure=objective.name))
    twin = side.twinx()
    twin.plot(
        xs,
        [100 * h["coverage"] for h in history],
        color="#636e72",
        linestyle="--",
        drawstyle="steps-post",
        label=_("cells filled"),
    )
    twin.set_ylabel(_("cells filled (%)"))
    (lines, labels), (more_lines, more_labels) = side.get_legend_handles_labels(), twin.get_legend_handles_labels()
    side.legend(
        lines + more_lines,
        labels + more_labels,
        loc="upper center",
        bbox_to_anchor=(0.5, -0.13),
        ncol=2,
        fontsize=8,
        frameon=False,
    )  # under the axes: inside, each legend covered one of the two lines
    side.set_title(_("search"), fontsize=11)
    fig.tight_layout()
    return save(fig, path)


def _better(objective: Measure) -> str:
    """The objective's axis: its name and which way is better, in the reader's language."""
    if objective.better == "low":
        return _("{measure} (low is better)").format(measure=objective.name)
    return _("{measure} (high is better)").format(measure=objective.name)


# --- report.md --------------------------------------------------------------------------------------------


def paired(objective: Measure, before: np.ndarray, after: np.ndarray) -> str:
    """The change in the objective, scenario by scenario (common random numbers), with two standard errors."""
    return paired_change(objective, before, after)[0]


def paired_change(objective: Measure, before: np.ndarray, after: np.ndarray) -> tuple[str, str]:
    """:func:`paired`'s text in the reader's language, and its verdict: "better", "worse" or "unclear"."""
    diff = np.asarray(after, dtype=float) - np.asarray(before, dtype=float)
    n = len(diff)
    mean = float(np.mean(diff))
    if n < 2:  # one scenario has no spread to weigh the change against
        return _("{mean} (one scenario, so no standard error): no clear difference").format(
            mean=number(mean, "+.3f")
        ), "unclear"
    se = float(np.std(diff, ddof=1) / math.sqrt(n))
    better = mean < 0 if objective.better == "low" else mean > 0
    verdict = ("better" if better else "worse") if abs(mean) > 2 * se else "unclear"
    said = {"better": _("better"), "worse": _("worse"), "unclear": _("no clear difference")}[verdict]
    return _("{mean} ± {spread} (two standard errors over {n} paired scenarios): {verdict}").format(
        mean=number(mean, "+.3f"), spread=number(2 * se, ".3f"), n=n, verdict=said
    ), verdict
