"""The evolve loop: prove (and if need be repair) the starting table, seed the archive with it, then
generation after generation ask the emitter for proved children, run them on the fleet, and offer them
to the archive, until the budget of fleet evaluations is spent.

Resuming: the whole run is a function of its inputs and seed; only proofs and fleet evaluations cost
time, and both are written to the output folder as they finish (``proofs.jsonl``,
``evaluations.jsonl``). The same command run again replays the loop from the start with those answers
(no proof and no robot run again) and goes on where it stopped, with the same children it would have
asked for had it never stopped.
"""

from __future__ import annotations

import json
import time
from collections import Counter
from collections.abc import Callable, Iterator, Sequence
from contextlib import closing
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import Any

from tablebot.diagnostics import Diagnostic, fail, notify
from tablebot.evolve.evaluate import Evaluator, Means
from tablebot.evolve.measures import Descriptor, Measure, default_range, fitness
from tablebot.evolve.operators import Space, vary
from tablebot.evolve.pool import Workers, proved_ahead, repaired
from tablebot.evolve.proofs import Prover, Verdict
from tablebot.evolve.repair import PREFERENCES, Repaired, Step
from tablebot.evolve.space import Candidate, Gene, start, to_table
from tablebot.files import append, json_records, write_text
from tablebot.i18n import N_, from_json, to_json
from tablebot.table import Table

TRIES_PER_CHILD = 30  # variations tried per child asked for before a generation gives up on it
STALLED = 5  # generations in a row without a single new proved child end the search


@dataclass(frozen=True)
class Settings:
    objective: Measure
    descriptors: tuple[Descriptor, ...]
    budget: int  # fleet evaluations, the start's included
    batch: int  # children asked for per generation
    seed: int


@dataclass
class Counts:
    """What the search did: children varied, discarded by a failed proof (per property), duplicates of
    tables already seen, evaluations run and served from the folder (a resumed run), generations."""

    varied: int = 0
    discarded: Counter = field(default_factory=Counter)
    duplicates: int = 0
    evaluated: int = 0
    resumed: int = 0
    generations: int = 0
    repair_s: float = 0.0  # seconds spent repairing the start
    fleet_s: float = 0.0  # seconds waiting for the fleet


@dataclass
class Outcome:
    start_key: str
    start_verdict: Verdict
    repairs: list[Repaired]  # one per repair preference, when the start broke a property
    seeds: list[str]  # what the archive started from: the start, or its repairs
    archive: Any
    candidates: dict[str, Candidate]
    means: dict[str, Means]
    order: list[str]  # keys in the order they were evaluated
    counts: Counts
    history: list[dict[str, float]]
    seconds: float = 0.0


class Store:
    """The output folder's record of the run: ``spec.json`` (what is searched: another spec in the same
    folder is refused) and ``evaluations.jsonl`` (one line per evaluated candidate, as it finishes)."""

    def __init__(self, folder: Path, spec: dict[str, Any]) -> None:
        self.folder, self.spec = folder, json.dumps(spec, indent=1, sort_keys=True) + "\n"
        self.path = folder / "evaluations.jsonl"
        self.proofs = folder / "proofs.jsonl"

    def open(self) -> dict[str, Means]:
        spec_file = self.folder / "spec.json"
        if spec_file.exists() and spec_file.read_text(encoding="utf-8") != self.spec:
            raise fail(
                self.folder,
                N_(
                    "--out holds another evolve run (another table, robot file, world, properties, "
                    "scenarios, objective, descriptors, limits or seed)"
                ),
                N_("give --out a new folder, or delete this one to start over"),
            )
        if not spec_file.exists():
            write_text(spec_file, self.spec)
        # a line cut by a kill is skipped: that candidate runs again
        return {item["key"]: item["means"] for item in json_records(self.path, ("key", "means"))}

    def repairs(self) -> list[Repaired] | None:
        """The repairs an earlier run of this folder found (``repairs.json``), or None."""
        path = self.folder / "repairs.json"
        if not path.exists():
            return None
        try:
            return [repaired_from_json(item) for item in json.loads(path.read_text(encoding="utf-8", errors="replace"))]
        except (ValueError, KeyError, TypeError, IndexError):  # written whole, so damaged or edited since
            notify(
                Diagnostic(
                    str(path),
                    None,
                    None,
                    N_("not the repairs evolve writes: the repair is made again"),
                    severity="note",
                )
            )
            return None

    def keep_repairs(self, repairs: Sequence[Repaired]) -> None:
        write_text(self.folder / "repairs.json", json.dumps([repaired_to_json(r) for r in repairs], indent=1) + "\n")

    def record(self, key: str, means: Means) -> None:
        with append(self.path) as f:
            f.write(json.dumps({"key": key, "means": means}, sort_keys=True) + "\n")


def gene_to_json(gene: Gene) -> dict[str, Any]:
    return {
        "state": gene.state,
        "events": sorted(gene.events),
        "motors": list(gene.motors),
        "timer": gene.timer,
        "next": gene.next,
        "description": to_json(gene.description),
        "counters": list(gene.counters),
        "lamps": list(gene.lamps),
        "origin": gene.origin,
        "note": to_json(gene.note),
    }


def gene_from_json(item: dict[str, Any]) -> Gene:
    return Gene(
        item["state"],
        frozenset(item["events"]),
        tuple(item["motors"]),
        item["timer"],
        item["next"],
        from_json(item["description"]),
        tuple(item["counters"]),
        tuple(item["lamps"]),
        item["origin"],
        from_json(item["note"]),
    )


def repaired_to_json(r: Repaired) -> dict[str, Any]:
    return {
        "candidate": [gene_to_json(g) for g in r.candidate],
        "failing": list(r.failing),
        "proposals": r.proposals,
        "steps": [
            {"prop": s.prop, "state": s.state, "gene": gene_to_json(s.gene), "ticks": s.counterexample_ticks}
            for s in r.steps
        ],
    }


def repaired_from_json(item: dict[str, Any]) -> Repaired:
    steps = [Step(s["prop"], s["state"], gene_from_json(s["gene"]), s["ticks"]) for s in item["steps"]]
    return Repaired(
        tuple(gene_from_json(g) for g in item["candidate"]), steps, tuple(item["failing"]), item["proposals"]
    )


def qd_module() -> ModuleType:
    """:mod:`tablebot.evolve.archive`, imported when first needed: it imports pyribs (pandas, scikit-learn,
    compiled numba functions: seconds), which a run does while its workers repair the start."""
    from tablebot.evolve import archive

    return archive


@dataclass
class Evolution:
    """One run: the starting table, what may change, the settings, and where proofs and runs happen."""

    base: Table
    space: Space
    settings: Settings
    prover: Prover
    evaluator: Evaluator
    store: Store
    workers: Workers
    on_eval: Callable[[int], None] = lambda n: None
    on_repair: Callable[[list[Repaired]], None] = lambda r: None

    def __post_init__(self) -> None:
        plan = self.evaluator.plan
        self.seconds = plan.spec.ticks * plan.scenes[0].tick_s
        self.known = self.store.open()
        self.candidates: dict[str, Candidate] = {}
        self.means: dict[str, Means] = {}
        self.order: list[str] = []
        self.counts = Counts()

    # --- the loop ------------------------------------------------------------------------------------

    def run(self) -> Outcome:
        started = time.perf_counter()
        first = start(self.base)
        start_key, verdict = self.prover.verdict(to_table(first, self.base))
        self.candidates[start_key] = first
        repairs: list[Repaired] = []
        seeds = [start_key]
        if not verdict.ok:
            began = time.perf_counter()
            stored = self.store.repairs()
            if stored is None:
                answers = [self.workers.submit(repaired, first, self.space, prefer) for prefer in PREFERENCES]
                qd_module()  # pyribs' seconds of imports while the workers repair
                stored = [answer.get() for answer in answers]
                self.store.keep_repairs(stored)
            repairs = stored
            self.counts.repair_s = time.perf_counter() - began
            self.on_repair(repairs)
            mended = [r for r in repairs if r.ok]
            if not mended:
                failing = sorted({name for r in repairs for name in r.failing})
                raise fail(
                    self.base.path,
                    N_(
                        "the table breaks {broken}, and evolve found no guard rows that mend it ({failing} still fail)",
                        broken=tuple(verdict.failed),
                        failing=tuple(failing),
                    ),
                    N_(
                        "mend the table by hand (tablebot check shows the counterexample), or give evolve "
                        "the properties it must keep with --properties"
                    ),
                )
            seeds = []
            for r in mended:
                key, _ = self.prover.verdict(to_table(r.candidate, self.base))
                self.candidates.setdefault(key, r.candidate)
                seeds.append(key)
        seeds = list(dict.fromkeys(seeds))
        self.evaluate(list(dict.fromkeys([start_key, *seeds])))
        qd = qd_module()
        objective = self.settings.objective
        worst = 0.0 if objective.better == "high" else -default_range(objective.name, self.seconds)[1]
        archive = qd.make_archive(self.settings.descriptors, worst, self.settings.seed)
        self.offer(archive, seeds)
        emitter = qd.TableEmitter(archive, self.breed, self.settings.batch, self.settings.seed)
        history = [self.snapshot(archive)]
        stalled = 0
        while len(self.order) < self.settings.budget and stalled < STALLED:
            keys = [str(k) for k in emitter.ask()][: self.settings.budget - len(self.order)]
            self.counts.generations += 1
            stalled = 0 if keys else stalled + 1
            if keys:
                self.evaluate(keys)
                self.offer(archive, keys)
                history.append(self.snapshot(archive))
        return Outcome(
            start_key,
            verdict,
            repairs,
            seeds,
            archive,
            self.candidates,
            self.means,
            self.order,
            self.counts,
            history,
            time.perf_counter() - started,
        )

    def breed(self, parents: Sequence[str], rng: Any, count: int) -> list[str]:
        """Up to ``count`` children of the parents that are proved and behave unlike any table seen. The
        children are varied in order and proved ahead in the workers; each is then taken in order, as if
        proved here, until ``count`` are in (the variations depend on ``rng`` alone, not on the verdicts)."""
        out: list[str] = []
        children = self.variations(parents, rng, count * TRIES_PER_CHILD)
        ahead = proved_ahead(self.workers, self.prover, children, self.workers.window)
        with closing(ahead):  # closed at the end: proofs not started are dropped
            for child, machine, key, found in ahead:
                if len(out) == count:
                    break
                if child is not None and machine is not None:
                    self.take(child, machine, key, found, out)
        return out

    def take(self, child: Candidate, machine: Any, key: str, found: Any, out: list[str]) -> None:
        """Count one varied child, and keep it (in ``out``) when it is proved and new."""
        self.counts.varied += 1
        key, verdict = self.prover.decide(machine, key, found)
        if not verdict.ok:
            self.counts.discarded[verdict.failed[0]] += 1
        elif key in self.candidates:
            self.counts.duplicates += 1
        else:
            self.candidates[key] = child
            out.append(key)

    def variations(self, parents: Sequence[str], rng: Any, tries: int) -> Iterator[Candidate | None]:
        """``tries`` children of parents drawn from ``parents`` (None where a variation gave nothing)."""
        for _ in range(tries):
            parent = self.candidates[parents[int(rng.integers(len(parents)))]]
            other = self.candidates[parents[int(rng.integers(len(parents)))]]
            yield vary(parent, self.space, rng, other if other is not parent else None)

    def evaluate(self, keys: Sequence[str]) -> None:
        """Means of every measure for each key: from the folder when an earlier run evaluated it, else on
        the fleet (each written to the folder as it finishes)."""
        new = []
        for key in keys:
            if key in self.known:
                self.means[key] = self.known[key]
                self.counts.resumed += 1
                self.on_eval(1)
            else:
                new.append(key)

        def done(key: str, means: Means, _values: Any) -> None:
            self.store.record(key, means)
            self.means[key] = means
            self.counts.evaluated += 1
            self.on_eval(1)

        if new:
            began = time.perf_counter()
            self.evaluator.run([(key, to_table(self.candidates[key], self.base)) for key in new], done)
            self.counts.fleet_s += time.perf_counter() - began
        self.order += list(keys)

    def offer(self, archive: Any, keys: Sequence[str]) -> None:
        objective = [fitness(self.settings.objective, self.means[k][self.settings.objective.name]) for k in keys]
        measures = [[self.means[k][d.name] for d in self.settings.descriptors] for k in keys]
        qd_module().add(archive, keys, objective, measures)

    def snapshot(self, archive: Any) -> dict[str, float]:
        stats = archive.stats
        best = fitness(self.settings.objective, float(stats.obj_max)) if stats.num_elites else float("nan")
        return {
            "evaluated": len(self.order),
            "best": best,
            "elites": int(stats.num_elites),
            "coverage": float(stats.coverage),
            "qd_score": float(stats.qd_score),
        }
