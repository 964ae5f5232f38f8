"""``report.md``'s text, in the reader's language (issue 38): the run, the robot's tables, the starting table
and its repairs, the search, the archive, the best tables against the start on fresh seeds, and every table
written with the commands that run it. User text (names of tables, states and properties, descriptions) is
escaped for markdown, numbers are written as the reader's language writes them (tablebot.i18n.number)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from tablebot.escape import markdown_code, markdown_text
from tablebot.evolve.commands import Replay, sim_commands, sweep_command
from tablebot.evolve.measures import Measure, fitness, measure_text
from tablebot.evolve.report import Written, paired_change
from tablebot.i18n import _, localise, ngettext, number
from tablebot.table import Table

if TYPE_CHECKING:
    from tablebot.evolve.evaluate import Evaluator, Means
    from tablebot.evolve.proofs import Prover
    from tablebot.evolve.run import Outcome, Settings
    from tablebot.evolve.whole import Whole

__all__ = ["Fresh", "measure_rows", "report_text"]


@dataclass
class Fresh:
    """Tables measured again on fresh scenarios: per key, the means and each scenario's numbers."""

    means: dict[str, Means] = field(default_factory=dict)
    values: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)


def _names(names: Sequence[str]) -> str:
    return ", ".join(markdown_text(name) for name in names)


def report_text(
    outcome: Outcome,
    settings: Settings,
    base: Table,
    prover: Prover,
    evaluator: Evaluator,
    check: Any,
    fresh: Fresh,
    written: list[Written],
    best: list[str],
    names: Sequence[str],
    replay: Replay,
) -> str:
    objective = settings.objective
    plan = evaluator.plan
    where, generations = Path(base.path), outcome.counts.generations
    heading = (
        _("# Evolving {table}: {objective} (high is better)")
        if objective.better == "high"
        else _("# Evolving {table}: {objective} (low is better)")
    )
    worlds = ngettext("{seeds} seeds × {n} world", "{seeds} seeds × {n} worlds", len(plan.spec.worlds))
    grids = "".join(f", --grid {markdown_text(g)}" for g in replay.grid)
    run = ngettext(
        "{tables} tables run on the fleet, each on {scenarios} scenarios ({worlds}{grids}, {seconds} s "
        "each), {n} generation of up to {batch}, seed {seed}; {wall} s.",
        "{tables} tables run on the fleet, each on {scenarios} scenarios ({worlds}{grids}, {seconds} s "
        "each), {n} generations of up to {batch}, seed {seed}; {wall} s.",
        generations,
    )
    lines = [
        heading.format(table=markdown_text(f"{where.parent.name}/{where.name}"), objective=objective.name),
        "",
        run.format(
            tables=len(outcome.order),
            scenarios=plan.spec.total,
            worlds=worlds.format(seeds=len(plan.spec.seeds), n=len(plan.spec.worlds)),
            grids=grids,
            seconds=number(plan.spec.ticks * plan.scenes[0].tick_s),
            n=generations,
            batch=settings.batch,
            seed=settings.seed,
            wall=number(outcome.seconds, ".0f"),
        ),
        "",
    ]
    lines += several_section(prover.whole)
    lines += start_section(outcome, base, f"{prover.whole.name}." if prover.whole is not None else "")
    lines += search_section(outcome, prover)
    lines += archive_section(outcome, settings)
    lines += fresh_section(outcome, objective, check, fresh, best, names)
    lines += tables_section(outcome, objective, written, replay, prover.whole)
    return "\n".join(lines) + "\n"


def several_section(whole: Whole | None) -> list[str]:
    """Of a robot of several tables: which table evolved, and that the others stayed as they are."""
    if whole is None:
        return []
    name, others = markdown_text(whole.name), _names(whole.others)
    return [
        _("## The robot's tables"),
        "",
        _(
            "The robot has {n} tables ({tables}); evolve changed table **{name}** only (`--table {name}`). The "
            "other tables ({others}) stayed exactly as they are: every candidate was proved over the product of "
            "all the tables and run on the fleet with all of them, the tables written here are {name} tables "
            "({name}.best-1.csv, ...), and no file of {others} was written."
        ).format(n=len(whole.tables.names), tables=_names(whole.tables.names), name=name, others=others),
        "",
    ]


def tables_section(
    outcome: Outcome, objective: Measure, written: list[Written], replay: Replay, whole: Whole | None = None
) -> list[str]:
    """Every table written, with the ``tablebot sim`` that runs it in each world (a folder of its own
    under OUT/sim for each), and the ``tablebot sweep`` that runs one on all the search's scenarios; of a
    robot of several tables, put in a copy of the robot's folder first (its robot file names its tables)."""
    several = len(replay.worlds) > 1
    simulate = (
        _("Simulate one as it was evolved, in each of the {n} worlds:").format(n=len(replay.worlds))
        if several
        else _("Simulate one as it was evolved:")
    )
    lines = [
        "",
        _("## The tables"),
        "",
        _(
            "Each is written in the document's layout with its `check` report beside it (`NAME.check.txt`); "
            "rows evolution changed say so in their description."
        )
        + " "
        + simulate,
        "",
    ]
    for w in written:
        status = _("every property holds") if w.holds else _("A PROPERTY FAILS")
        head = _("- {file} ({status}; {objective} {value} on the search scenarios)").format(
            file=markdown_code(f"{w.label}.csv"),
            status=status,
            objective=objective.name,
            value=number(outcome.means[w.key][objective.name], ".3f"),
        )
        commands = sim_commands(w.path, w.label, replay, whole)
        if several:
            lines += [
                f"{head}:",
                *(
                    _("  - in {world}: {command}").format(world=markdown_text(world), command=markdown_code(command))
                    for world, (_name, command) in zip(replay.worlds, commands, strict=True)
                ),
            ]
        else:
            lines.append(f"{head}: {markdown_code(commands[0][1])}")
    if written:
        first = next((w for w in written if w.label.rsplit(".", 1)[-1] == "best-1"), written[0])
        lines += [
            "",
            _(
                "Run a table on every scenario and world it was evolved on at once ({label} here; any table "
                "above in its place):"
            ).format(label=markdown_code(first.label)),
            "",
            markdown_code(sweep_command(first.path, first.label, replay, whole)),
        ]
    return lines


def start_section(outcome: Outcome, base: Table, own: str = "") -> list[str]:
    lines = [_("## The starting table"), ""]
    if outcome.start_verdict.ok:
        return [*lines, _("Every property holds in it: the archive starts from it as it is."), ""]
    lines.append(
        _(
            "It breaks {properties}, so no table evolved from it could be kept until it was repaired. The "
            "repair (guided by `check`'s shortest counterexamples) added:"
        ).format(properties=_names(outcome.start_verdict.failed))
    )
    for k, repaired in enumerate(outcome.repairs):
        label = own + ("repaired.csv" if k == 0 else f"repaired-{k + 1}.csv")
        done = (
            _("every property holds")
            if repaired.ok
            else _("still failing: {properties}").format(properties=_names(repaired.failing))
        )
        rows = ngettext(
            "**{label}** ({n} guard row, {proposals} proposals checked; {done}):",
            "**{label}** ({n} guard rows, {proposals} proposals checked; {done}):",
            len(repaired.steps),
        )
        lines += [
            "",
            rows.format(label=markdown_text(label), n=len(repaired.steps), proposals=repaired.proposals, done=done),
            "",
        ]
        lines += [
            _("- {state}: {row} (its counterexample was {ticks} ticks)").format(
                state=markdown_text(_state(base, s.state)),
                row=markdown_code(str(localise(s.gene.description))),
                ticks=s.counterexample_ticks,
            )
            for s in repaired.steps
        ]
    return [*lines, ""]


def _state(base: Table, state: Any) -> str:
    name = base.state_name(state)
    return f"{state} · {name}" if name else _("state {state}").format(state=state)


def search_section(outcome: Outcome, prover: Prover) -> list[str]:
    c = outcome.counts
    why = ", ".join(f"{markdown_text(name)} {count}" for name, count in c.discarded.most_common()) or _("none")
    return [
        _("## The search"),
        "",
        _(
            "{varied} tables varied from the archive's elites; {discarded} discarded because a property failed "
            "(the first that failed: {why}); {duplicates} behaved exactly like a table seen before; {evaluated} "
            "run on the fleet now, {resumed} taken from an earlier run in this folder."
        ).format(
            varied=c.varied,
            discarded=sum(c.discarded.values()),
            why=why,
            duplicates=c.duplicates,
            evaluated=c.evaluated,
            resumed=c.resumed,
        ),
        "",
        _(
            "Proofs: {proved} run ({seconds} s), {hits} answered from the cache (canonical form of the compiled "
            "machine). Repair {repair} s; waiting for the fleet {fleet} s."
        ).format(
            proved=prover.proved,
            seconds=number(prover.seconds, ".1f"),
            hits=prover.hits,
            repair=number(c.repair_s, ".1f"),
            fleet=number(c.fleet_s, ".1f"),
        ),
        "",
    ]


def archive_section(outcome: Outcome, settings: Settings) -> list[str]:
    stats = outcome.archive.stats
    ranges = ", ".join(
        _("{name} {low}..{high} in {cells} cells").format(
            name=markdown_text(d.name), low=number(d.low), high=number(d.high), cells=d.cells
        )
        for d in settings.descriptors
    )
    return [
        _("## The archive"),
        "",
        ngettext(
            "MAP-Elites (pyribs GridArchive) over {ranges}: {elites} elite, {share} % of the cells.",
            "MAP-Elites (pyribs GridArchive) over {ranges}: {elites} elites, {share} % of the cells.",
            stats.num_elites,
        ).format(ranges=ranges, elites=stats.num_elites, share=number(100 * float(stats.coverage), ".0f")),
        "",
        "![{alt}](archive.png)".format(alt=markdown_text(_("the archive"))),
        "",
    ]


def fresh_section(
    outcome: Outcome, objective: Measure, check: Any, fresh: Fresh, best: list[str], names: Sequence[str]
) -> list[str]:
    start = outcome.start_key
    columns = [(_("starting table"), fresh.means[start])]
    if outcome.repairs:
        columns += [
            ("repaired" if k == 0 else f"repaired-{k + 1}", fresh.means[key]) for k, key in enumerate(outcome.seeds)
        ]
    columns += [(f"best-{k + 1}", fresh.means[key]) for k, key in enumerate(best)]
    lines = [
        _("## Before and after, on fresh seeds"),
        "",
        _("Measured again on {n} scenarios none of them was chosen on (seeds {first}..{last}):").format(
            n=check.spec.total, first=check.spec.seeds[0], last=check.spec.seeds[-1]
        ),
        "",
    ]
    lines += measure_rows(list(names), columns, objective)
    if best:
        after = fresh.values[best[0]][objective.name]
        lines += [
            "",
            _("best-1 against the starting table, {objective} per scenario: {change}.").format(
                objective=objective.name, change=paired_change(objective, fresh.values[start][objective.name], after)[0]
            ),
        ]
        kept = [k for k in outcome.seeds if k != start]
        if kept:
            lines.append(
                _("best-1 against the repaired table: {change}.").format(
                    change=paired_change(objective, fresh.values[kept[0]][objective.name], after)[0]
                )
            )
        if not outcome.start_verdict.ok:
            lines.append(
                _(
                    "(The starting table breaks a property: every table evolve keeps is proved to satisfy "
                    "them all, so the fair comparison for the search itself is against the repaired table.)"
                )
            )
    score = {key: fitness(objective, means[objective.name]) for key, means in fresh.means.items()}
    if not best:
        return [*lines, "", _("Better than the starting table on fresh seeds: no table was kept.")]
    _text, clear = paired_change(objective, fresh.values[start][objective.name], fresh.values[best[0]][objective.name])
    verdict = (
        _("no")
        if score[best[0]] <= score[start]
        else _("yes, beyond two standard errors")
        if clear == "better"
        else _("on the mean only, not clearly")
    )
    lines += ["", _("Better than the starting table on fresh seeds: {verdict}.").format(verdict=verdict)]
    return lines


def measure_rows(
    names: Sequence[str], columns: Sequence[tuple[str, dict[str, float]]], objective: Measure
) -> list[str]:
    """A markdown table: one row per measure, one column per table compared."""
    lines = [
        "| " + " | ".join([_("mean over the fresh scenarios"), *(markdown_text(c) for c, _m in columns)]) + " |",
        "|---" * (len(columns) + 1) + "|",
    ]
    for name in names:
        mark = ""
        if name == objective.name:
            mark = " " + (
                _("(objective, high is better)") if objective.better == "high" else _("(objective, low is better)")
            )
        cells = [
            f"{markdown_text(name)}{mark}: {markdown_text(measure_text(name))}",
            *(number(means[name], ".3f") for _c, means in columns),
        ]
        lines.append("| " + " | ".join(cells) + " |")
    return lines
