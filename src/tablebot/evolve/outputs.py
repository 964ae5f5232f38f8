"""The end of a run: the starting table, its repairs and the best tables measured again on fresh seeds,
and every file a person reads written to the output folder (see :mod:`tablebot.evolve.report`)."""

from __future__ import annotations

import hashlib
import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from tablebot.evolve import archive as qd
from tablebot.evolve.evaluate import Evaluator, Means
from tablebot.evolve.pool import Workers, check_report
from tablebot.evolve.proofs import Prover
from tablebot.evolve.report import Replay, as_table, heat_map, write_table
from tablebot.evolve.report_md import Fresh, report_text
from tablebot.evolve.run import Outcome, Settings
from tablebot.files import remove, write_text
from tablebot.fileset import current, file_set
from tablebot.i18n import current as current_language
from tablebot.i18n import gettext
from tablebot.table import Table

BEST = 3  # best tables written (elites of the best cells)


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
    digests = {
        str(p.relative_to(out)): hashlib.sha256(current(p).read_bytes()).hexdigest()
        for p in paths
        if current(p).is_file()
    }  # the files as written into the set, before it is swapped in
    return write_text(out / MANIFEST, json.dumps(digests, indent=1, sort_keys=True) + "\n")


def write_all(
    outcome: Outcome,
    settings: Settings,
    base: Table,
    prover: Prover,
    evaluator: Evaluator,
    check: Any,
    out: Path,
    names: Sequence[str],
    replay: Replay,
    workers: Workers,
) -> list[Path]:
    """Every table, check report, the heat map, evaluations.csv and report.md, replacing the previous run's
    all at once (tablebot.fileset); returns the paths written."""
    with file_set(out):
        return _write_all(outcome, settings, base, prover, evaluator, check, out, names, replay, workers)


def _write_all(
    outcome: Outcome,
    settings: Settings,
    base: Table,
    prover: Prover,
    evaluator: Evaluator,
    check: Any,
    out: Path,
    names: Sequence[str],
    replay: Replay,
    workers: Workers,
) -> list[Path]:
    forget_own(out)
    best = best_keys(outcome)
    start, seeds = outcome.start_key, outcome.seeds
    own = f"{prover.whole.name}." if prover.whole is not None else ""  # one of several tables: lights.best-1.csv
    tables = [
        (own + ("repaired" if k == 0 else f"repaired-{k + 1}"), key)
        for k, key in enumerate(seeds if outcome.repairs else [])
    ]
    tables += [(f"{own}best-{k + 1}", key) for k, key in enumerate(best)]
    tables += [
        (f"elites/{own}cell-" + "-".join(f"{c:02d}" for c in cell), key)
        for key, _, _, cell in qd.elites(outcome.archive)
    ]
    ready = [as_table(outcome.candidates[key], base, out / f"{label}.csv") for label, key in tables]
    language = current_language()  # the workers' processes speak it only when told
    checks = [workers.submit(check_report, table, language) for table in ready]  # in the workers while the fleet runs
    fresh = measure_fresh(evaluator, check, outcome, [start, *seeds, *best], base)
    written = [
        write_table(table, label, key, answer.get())
        for (label, key), table, answer in zip(tables, ready, checks, strict=True)
    ]
    start_at = tuple(outcome.means[start][d.name] for d in settings.descriptors)
    label = (
        gettext("the starting table")
        if outcome.start_verdict.ok  # the archive picture's legend
        else gettext("the starting table (breaks a property: not kept)")
    )
    paths = [
        heat_map(
            outcome.archive,
            settings.descriptors,
            settings.objective,
            outcome.history,
            start_at,
            out / "archive.png",
            label,
        ),
        write_evaluations(outcome, settings, out / "evaluations.csv"),
    ]
    text = report_text(outcome, settings, base, prover, evaluator, check, fresh, written, best, names, replay)
    paths.append(write_text(out / "report.md", text))
    remember_own(out, [p for w in written for p in (w.path, w.check)])
    return [*paths, *(w.path for w in written)]


def write_evaluations(outcome: Outcome, settings: Settings, path: Path) -> Path:
    from tablebot.fleet.plan import csv_text

    names = [settings.objective.name, *(d.name for d in settings.descriptors if d.name != settings.objective.name)]
    in_archive = {key for key, *_ in qd.elites(outcome.archive)}
    rows = [
        {
            "evaluation": k,
            "key": key,
            **{n: round(outcome.means[key][n], 6) for n in names},
            "elite": int(key in in_archive),
        }
        for k, key in enumerate(outcome.order)
    ]
    return write_text(path, csv_text(["evaluation", "key", *names, "elite"], rows))
