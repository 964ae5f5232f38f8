"""The end of a run: the starting table, its repairs and the best tables measured again on fresh seeds,
and every file a person reads written to the output folder (see :mod:`tablebot.evolve.report`)."""

from __future__ import annotations

import hashlib
import json
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from tablebot.evolve import archive as qd
from tablebot.evolve.evaluate import Evaluator, Means
from tablebot.evolve.measures import Measure, fitness
from tablebot.evolve.pool import Workers, check_report
from tablebot.evolve.proofs import Prover
from tablebot.evolve.report import (
    Replay,
    Written,
    as_table,
    heat_map,
    measure_rows,
    paired,
    sim_commands,
    sweep_command,
    write_table,
)
from tablebot.evolve.run import Outcome, Settings
from tablebot.files import remove, write_text
from tablebot.fileset import current, file_set
from tablebot.i18n import gettext
from tablebot.table import Table

if TYPE_CHECKING:
    from tablebot.evolve.whole import Whole

BEST = 3  # best tables written (elites of the best cells)


@dataclass
class Fresh:
    """Tables measured again on fresh scenarios: per key, the means and each scenario's numbers."""

    means: dict[str, Means] = field(default_factory=dict)
    values: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)


def measure_fresh(evaluator: Evaluator, check: Any, outcome: Outcome, keys: Sequence[str], base: Table) -> Fresh:
    from tablebot.evolve.space import to_table

    fresh = Fresh()

    def done(key: str, means: Means, values: dict[str, np.ndarray]) -> None:
        fresh.means[key], fresh.values[key] = means, values

    evaluator.run([(key, to_table(outcome.candidates[key], base)) for key in dict.fromkeys(keys)], done, check)
    return fresh


def best_keys(outcome: Outcome, count: int = BEST) -> list[str]:
    """The best elites (the archive holds the best table of every cell it has seen, so the best overall)."""
    return [key for key, *_ in qd.elites(outcome.archive)[:count]]


MANIFEST = "written.json"


def forget_own(out: Path) -> None:
    """Remove the tables an earlier run of this folder wrote, where they are still as it wrote them (a run
    writes them afresh); a table a person has changed since stays, and writing over it needs --force."""
    manifest = out / MANIFEST
    if not manifest.exists():
        return
    for name, digest in json.loads(manifest.read_text(encoding="utf-8")).items():
        path = out / name
        if path.is_file() and hashlib.sha256(path.read_bytes()).hexdigest() == digest:
            remove(path)  # inside write_all's set: gone when the new tables are swapped in


def remember_own(out: Path, paths: Sequence[Path]) -> Path:
    digests = {str(p.relative_to(out)): hashlib.sha256(current(p).read_bytes()).hexdigest() for p in paths
               if current(p).is_file()}  # the files as written into the set, before it is swapped in
    return write_text(out / MANIFEST, json.dumps(digests, indent=1, sort_keys=True) + "\n")


def write_all(outcome: Outcome, settings: Settings, base: Table, prover: Prover, evaluator: Evaluator, check: Any,
              out: Path, names: Sequence[str], replay: Replay, workers: Workers) -> list[Path]:
    """Every table, check report, the heat map, evaluations.csv and report.md, replacing the previous run's
    all at once (tablebot.fileset); returns the paths written."""
    with file_set(out):
        return _write_all(outcome, settings, base, prover, evaluator, check, out, names, replay, workers)


def _write_all(outcome: Outcome, settings: Settings, base: Table, prover: Prover, evaluator: Evaluator, check: Any,
               out: Path, names: Sequence[str], replay: Replay, workers: Workers) -> list[Path]:
    forget_own(out)
    best = best_keys(outcome)
    start, seeds = outcome.start_key, outcome.seeds
    own = f"{prover.whole.name}." if prover.whole is not None else ""  # one of several tables: lights.best-1.csv
    tables = [(own + ("repaired" if k == 0 else f"repaired-{k + 1}"), key)
              for k, key in enumerate(seeds if outcome.repairs else [])]
    tables += [(f"{own}best-{k + 1}", key) for k, key in enumerate(best)]
    tables += [(f"elites/{own}cell-" + "-".join(f"{c:02d}" for c in cell), key)
               for key, _, _, cell in qd.elites(outcome.archive)]
    ready = [as_table(outcome.candidates[key], base, out / f"{label}.csv") for label, key in tables]
    checks = [workers.submit(check_report, table) for table in ready]  # in the workers while the fleet runs
    fresh = measure_fresh(evaluator, check, outcome, [start, *seeds, *best], base)
    written = [write_table(table, label, key, answer.get())
               for (label, key), table, answer in zip(tables, ready, checks, strict=True)]
    start_at = tuple(outcome.means[start][d.name] for d in settings.descriptors)
    label = (gettext("the starting table") if outcome.start_verdict.ok  # the archive picture's legend
             else gettext("the starting table (breaks a property: not kept)"))
    paths = [heat_map(outcome.archive, settings.descriptors, settings.objective, outcome.history, start_at,
                      out / "archive.png", label),
             write_evaluations(outcome, settings, out / "evaluations.csv")]
    text = report_text(outcome, settings, base, prover, evaluator, check, fresh, written, best, names, replay)
    paths.append(write_text(out / "report.md", text))
    remember_own(out, [p for w in written for p in (w.path, w.check)])
    return [*paths, *(w.path for w in written)]


def write_evaluations(outcome: Outcome, settings: Settings, path: Path) -> Path:
    from tablebot.fleet.plan import csv_text

    names = [settings.objective.name, *(d.name for d in settings.descriptors if d.name != settings.objective.name)]
    in_archive = {key for key, *_ in qd.elites(outcome.archive)}
    rows = [{"evaluation": k, "key": key, **{n: round(outcome.means[key][n], 6) for n in names},
             "elite": int(key in in_archive)} for k, key in enumerate(outcome.order)]
    return write_text(path, csv_text(["evaluation", "key", *names, "elite"], rows))


def report_text(outcome: Outcome, settings: Settings, base: Table, prover: Prover, evaluator: Evaluator, check: Any,
                fresh: Fresh, written: list[Written], best: list[str], names: Sequence[str], replay: Replay) -> str:
    objective = settings.objective
    plan = evaluator.plan
    seconds = plan.spec.ticks * plan.scenes[0].tick_s
    where, generations = Path(base.path), outcome.counts.generations
    lines = [f"# Evolving {where.parent.name}/{where.name}: {objective.name} ({objective.better} is better)", "",
             f"{len(outcome.order)} tables run on the fleet, each on {plan.spec.total} scenarios "
             f"({len(plan.spec.seeds)} seeds × {len(plan.spec.worlds)} world(s)"
             f"{''.join(f', --grid {g}' for g in replay.grid)}, {seconds:g} s each), "
             f"{generations} generation{'' if generations == 1 else 's'} of up to {settings.batch}, "
             f"seed {settings.seed}; "
             f"{outcome.seconds:.0f} s.", ""]
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
    others = ", ".join(whole.others)
    return ["## The robot's tables", "",
            f"The robot has {len(whole.tables.names)} tables ({', '.join(whole.tables.names)}); evolve changed "
            f"table **{whole.name}** only (`--table {whole.name}`). The other tables ({others}) stayed exactly as "
            "they are: every candidate was proved over the product of all the tables and run on the fleet with "
            f"all of them, the tables written here are {whole.name} tables ({whole.name}.best-1.csv, ...), and no "
            f"file of {others} was written.", ""]


def tables_section(outcome: Outcome, objective: Measure, written: list[Written], replay: Replay,
                   whole: Whole | None = None) -> list[str]:
    """Every table written, with the ``tablebot sim`` that runs it in each world (a folder of its own
    under OUT/sim for each), and the ``tablebot sweep`` that runs one on all the search's scenarios; of a
    robot of several tables, put in a copy of the robot's folder first (its robot file names its tables)."""
    several = len(replay.worlds) > 1
    lines = ["", "## The tables", "",
             "Each is written in the document's layout with its `check` report beside it (`NAME.check.txt`); "
             "rows evolution changed say so in their description. Simulate one as it was evolved"
             + (f", in each of the {len(replay.worlds)} worlds:" if several else ":"), ""]
    for w in written:
        status = "every property holds" if w.holds else "A PROPERTY FAILS"
        head = (f"- `{w.label}.csv` ({status}; {objective.name} {outcome.means[w.key][objective.name]:.3f} on the "
                "search scenarios)")
        commands = sim_commands(w.path, w.label, replay, whole)
        if several:
            lines += [f"{head}:", *(f"  - in {world}: `{command}`"
                                    for world, (_, command) in zip(replay.worlds, commands, strict=True))]
        else:
            lines.append(f"{head}: `{commands[0][1]}`")
    if written:
        first = next((w for w in written if w.label.rsplit(".", 1)[-1] == "best-1"), written[0])
        lines += ["", f"Run a table on every scenario and world it was evolved on at once (`{first.label}` here; "
                  "any table above in its place):", "",
                  f"`{sweep_command(first.path, first.label, replay, whole)}`"]
    return lines


def start_section(outcome: Outcome, base: Table, own: str = "") -> list[str]:
    lines = ["## The starting table", ""]
    if outcome.start_verdict.ok:
        return [*lines, "Every property holds in it: the archive starts from it as it is.", ""]
    lines.append(f"It breaks {', '.join(outcome.start_verdict.failed)}, so no table evolved from it could be kept "
                 "until it was repaired. The repair (guided by `check`'s shortest counterexamples) added:")
    for k, repaired in enumerate(outcome.repairs):
        label = own + ("repaired.csv" if k == 0 else f"repaired-{k + 1}.csv")
        done = "every property holds" if repaired.ok else f"still failing: {', '.join(repaired.failing)}"
        lines += ["", f"**{label}** ({len(repaired.steps)} guard rows, {repaired.proposals} proposals checked; "
                  f"{done}):", ""]
        lines += [f"- state {base.state_title(s.state)}: `{s.gene.description}` (its counterexample was "
                  f"{s.counterexample_ticks} ticks)" for s in repaired.steps]
    return [*lines, ""]


def search_section(outcome: Outcome, prover: Prover) -> list[str]:
    c = outcome.counts
    discarded = sum(c.discarded.values())
    why = ", ".join(f"{name} {count}" for name, count in c.discarded.most_common()) or "none"
    return ["## The search", "",
            f"{c.varied} tables varied from the archive's elites; {discarded} discarded because a property failed "
            f"(the first that failed: {why}); {c.duplicates} behaved exactly like a table seen before; "
            f"{c.evaluated} run on the fleet now, {c.resumed} taken from an earlier run in this folder.", "",
            f"Proofs: {prover.proved} run ({prover.seconds:.1f} s), {prover.hits} answered from the cache "
            f"(canonical form of the compiled machine). Repair {c.repair_s:.1f} s; waiting for the fleet "
            f"{c.fleet_s:.1f} s.", ""]


def archive_section(outcome: Outcome, settings: Settings) -> list[str]:
    stats = outcome.archive.stats
    ranges = ", ".join(f"{d.name} {d.low:g}..{d.high:g} in {d.cells} cells" for d in settings.descriptors)
    return ["## The archive", "", f"MAP-Elites (pyribs GridArchive) over {ranges}: {stats.num_elites} elites, "
            f"{100 * float(stats.coverage):.0f} % of the cells.", "", "![the archive](archive.png)", ""]


def fresh_section(outcome: Outcome, objective: Measure, check: Any, fresh: Fresh, best: list[str],
                  names: Sequence[str]) -> list[str]:
    start = outcome.start_key
    columns = [("starting table", fresh.means[start])]
    if outcome.repairs:
        columns += [("repaired" if k == 0 else f"repaired-{k + 1}", fresh.means[key])
                    for k, key in enumerate(outcome.seeds)]
    columns += [(f"best-{k + 1}", fresh.means[key]) for k, key in enumerate(best)]
    lines = ["## Before and after, on fresh seeds", "",
             f"Measured again on {check.spec.total} scenarios none of them was chosen on (seeds "
             f"{check.spec.seeds[0]}..{check.spec.seeds[-1]}):", ""]
    lines += measure_rows(list(names), columns, objective)
    if best:
        after = fresh.values[best[0]][objective.name]
        lines += ["", f"best-1 against the starting table, {objective.name} per scenario: "
                  f"{paired(objective, fresh.values[start][objective.name], after)}."]
        kept = [k for k in outcome.seeds if k != start]
        if kept:
            lines.append(f"best-1 against the repaired table: "
                         f"{paired(objective, fresh.values[kept[0]][objective.name], after)}.")
        if not outcome.start_verdict.ok:
            lines.append("(The starting table breaks a property: every table evolve keeps is proved to satisfy them "
                         "all, so the fair comparison for the search itself is against the repaired table.)")
    score = {key: fitness(objective, means[objective.name]) for key, means in fresh.means.items()}
    if not best:
        return [*lines, "", "Better than the starting table on fresh seeds: no table was kept."]
    change = paired(objective, fresh.values[start][objective.name], fresh.values[best[0]][objective.name])
    verdict = "no" if score[best[0]] <= score[start] else \
        "yes, beyond two standard errors" if change.endswith(": better") else "on the mean only, not clearly"
    lines += ["", f"Better than the starting table on fresh seeds: {verdict}."]
    return lines
