"""Proving candidates: every property of the robot (its file's ``[properties]`` and the property files
``check`` would read), proved exhaustively by ``tablebot check``'s own search, and no error-level
finding (a zero-time loop nothing can leave). Verdicts are cached on the compiled machine's canonical
form, so a candidate that behaves like one already proved (rows reordered where they never overlap,
a shadowed row added, descriptions changed) is never proved twice; the cache is a JSON Lines file, so
a resumed run proves nothing again.
"""

from __future__ import annotations

import hashlib
import json
import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from tablebot.analysis.check import CheckReport, run_check
from tablebot.analysis.loops import zero_time_loops
from tablebot.analysis.model import Model
from tablebot.analysis.properties import Property, load_properties
from tablebot.analysis.prove import Result, check_property, first_violation
from tablebot.diagnostics import fail
from tablebot.files import append, json_records
from tablebot.i18n import N_
from tablebot.machine import Machine, compile_table
from tablebot.table import Table

if TYPE_CHECKING:
    from tablebot.evolve.whole import Whole


def canonical(machine: Machine) -> str:
    """A digest of what the machine does: per state (by name), for every combination of the events, the
    effect of the row that fires (outputs, timer, counter loads, next state) or nothing; plus the start.
    Row order, descriptions and file lines do not enter it; states enter by name (properties name them)."""
    flat = machine.flat
    if flat is None:
        raise ValueError("canonical form needs a table of at most FLAT_BITS event columns")
    width = 1 << len(machine.table.events)
    rows = machine.rows

    def effect(index: int) -> list | None:
        if index < 0:
            return None
        row = rows[index]
        return [str(machine.states[row.next]), row.timer, list(row.outputs), list(row.loads)]

    per_state = {
        str(state): [effect(flat[s * width + e]) for e in range(width)] for s, state in enumerate(machine.states)
    }
    data = {
        "events": list(machine.table.events),
        "outputs": list(machine.output_names),
        "start": [str(machine.states[machine.initial_state]), machine.initial_timer],
        "states": dict(sorted(per_state.items())),
    }
    return hashlib.sha256(json.dumps(data, separators=(",", ":")).encode()).hexdigest()[:24]


@dataclass(frozen=True)
class Verdict:
    """Whether a candidate may be kept; ``failed`` names what broke (properties, error findings)."""

    ok: bool
    failed: tuple[str, ...] = ()


@dataclass
class Prover:
    """Proves candidates against the properties of ``files`` (plus the robot file's), caching verdicts by
    canonical form in ``cache_path`` (JSON Lines; None: in memory only)."""

    files: Sequence[Path]
    cache_path: Path | None = None
    verdicts: dict[str, Verdict] = field(default_factory=dict)
    proved: int = 0  # proofs actually run (not served from the cache)
    hits: int = 0
    seconds: float = 0.0
    failures: dict[str, int] = field(default_factory=dict)  # proofs each property failed (ordering only)
    names: list[str] = field(default_factory=list)  # the property list's names, as last read
    #: a robot of several tables: the table evolved and the others as they are (None: a robot of one table)
    whole: Whole | None = None
    fixed: dict[str, Result] = field(default_factory=dict)  # results of properties no candidate can change

    def __post_init__(self) -> None:
        if self.cache_path is not None:
            for item in json_records(self.cache_path, ("key", "ok", "failed")):
                self.verdicts[item["key"]] = Verdict(bool(item["ok"]), tuple(item["failed"]))

    def properties(self, machine: Machine) -> list[Property]:
        """The properties read against this machine (its states and outputs; of several tables, the robot's
        with the candidate in its place: a property may name any table's states)."""
        if self.whole is None:
            return load_properties(machine, list(self.files))
        robot = self.whole.robot(machine)
        return load_properties(robot.machines[0], list(self.files), robot)

    def check(self, prop: Property, machine: Machine) -> Result:
        """``check``'s proof of one property for the candidate ``machine`` (of several tables: over the product
        of the robot's tables, the candidate in its place; a property it cannot change, proved once)."""
        if self.whole is None:
            return check_property(prop, machine)
        from tablebot.analysis.prove_product import check_product_property

        if self.whole.depends(prop):
            return check_product_property(prop, self.whole.robot(machine))
        if prop.name not in self.fixed:
            self.fixed[prop.name] = check_product_property(prop, self.whole.tables)
        return self.fixed[prop.name]

    def violation(self, prop: Property, machine: Machine, inputs: Any) -> int | None:
        """The tick at which ``inputs`` (a counterexample) break ``prop`` in the candidate, or None."""
        if self.whole is None:
            from tablebot.replay import replay

            return first_violation(prop, machine, replay(machine, inputs))
        from tablebot.analysis import prove_product

        return prove_product.first_violation(prop, self.whole.robot(machine), inputs)

    def report(self, machine: Machine) -> CheckReport:
        """The whole ``check`` of one machine (findings and every property, counterexamples included; of
        several tables, of the robot with the candidate in its place)."""
        if self.whole is None:
            return run_check(machine, self.properties(machine))
        from tablebot.analysis.check_tables import run_check_tables

        return run_check_tables(self.whole.robot(machine), self.properties(machine))

    def stuck(self, machine: Machine) -> bool:
        """Whether a zero-time loop no input can leave traps the candidate (its own table: the others stay as
        they are, and a cross-table column is free there, as an input is)."""
        return any(f.severity == "error" for f in zero_time_loops(Model(machine).explore()))

    def results(self, machine: Machine) -> tuple[list[Result], bool]:
        """Every property's result (counterexamples included) and whether a zero-time loop traps the
        robot: what a repair weighs, without check's other findings."""
        return [self.check(prop, machine) for prop in self.properties(machine)], self.stuck(machine)

    def verdict(self, table: Table) -> tuple[str, Verdict]:
        """The candidate's canonical key and verdict (proved now, or from the cache)."""
        machine = compile_table(table)
        return self.decide(machine, canonical(machine))

    def decide(self, machine: Machine, key: str, found: Any = None) -> tuple[str, Verdict]:
        """The verdict of a machine of canonical ``key``: from the cache, or proved now, using what a worker
        found (``found``: an answer of :func:`tablebot.evolve.pool.statuses`, or None)."""
        import time

        if key in self.verdicts:
            self.hits += 1
            return key, self.counted(self.verdicts[key])
        started = time.perf_counter()
        known, stuck = found.get() if found is not None else ({}, None)
        verdict = self.prove(machine, known, stuck)
        self.seconds += time.perf_counter() - started
        self.proved += 1
        self.verdicts[key] = verdict
        if self.cache_path is not None:
            with append(self.cache_path) as f:  # one line per proof: a cut run keeps them
                f.write(json.dumps({"key": key, "ok": verdict.ok, "failed": list(verdict.failed)}) + "\n")
        return key, self.counted(verdict)

    def counted(self, verdict: Verdict) -> Verdict:
        """Count a failed verdict for the property that failed, whether proved now or read from the cache:
        the order properties are tried in then follows the calls alone, so a resumed run (its verdicts read
        from the folder) names the same first failing property as a run never stopped."""
        if not verdict.ok:
            self.failures[verdict.failed[0]] = self.failures.get(verdict.failed[0], 0) + 1
        return verdict

    def order(self, machine: Machine | None = None) -> list[int]:
        """Places in the property list, in the order they are tried now: the one that failed most often so
        far first (ties in list order). The list's names are read once (from ``machine`` if need be): every
        candidate has the same properties."""
        if not self.names and machine is not None:
            self.names = [p.name for p in self.properties(machine)]
        names = self.names
        return sorted(range(len(names)), key=lambda k: -self.failures.get(names[k], 0))

    def prove(self, machine: Machine, known: dict[int, bool] | None = None, stuck: bool | None = None) -> Verdict:
        """Every property in turn (:meth:`order`), stopping at the first that fails; then the zero-time loops
        no input can leave (``check``'s only error-level finding about behaviour). A property "fails" when
        ``check`` does not prove it (violated or unknown). ``known``: properties (by place) already proved
        or refuted elsewhere; ``stuck``: whether a zero-time loop traps it, when already looked at."""
        props = self.properties(machine)
        self.names = [p.name for p in props]
        for index in self.order():
            holds = (known or {}).get(index)
            if holds is None:
                holds = self.check(props[index], machine).status == "holds"
            if not holds:
                return Verdict(False, (props[index].name,))
        if stuck is None:
            stuck = self.stuck(machine)
        return Verdict(False, ("zero-time-loop",)) if stuck else Verdict(True)


LINE_WORD = re.compile(r"(?<![\w.-])line(?![\w.-])")  # the condition language's ``line`` (conditions.TOKEN_RE)


def refuse_line_conditions(prover: Prover, machine: Machine) -> None:
    """Properties that name file lines (``line == 14``) lose their meaning once rows are added, removed
    or moved: refused before the search starts, naming the property."""
    for prop in prover.properties(machine):
        texts = [c.text for c in (prop.cond, prop.when, prop.then) if c is not None]
        if any(LINE_WORD.search(text) for text in texts):
            where = f"{prop.source}:{prop.line}" if prop.line else prop.source
            raise fail(
                where,
                N_(
                    "property {name} names a file line; evolve adds, removes and moves rows, so a line "
                    "number would name another row",
                    name=prop.name,
                ),
                N_(
                    "write the property with states, events and outputs instead of line (or give evolve "
                    "other properties with --properties)"
                ),
            )


def refuse_fixed(whole: Whole, prover: Prover) -> None:
    """Before the search: a property the evolved table cannot change that fails in the robot as it is would
    discard every candidate. Said, naming the property, the table that decides it and ``--table``."""
    robot = whole.tables
    for prop in prover.properties(robot.machines[whole.index]):
        if whole.depends(prop) or prover.check(prop, robot.machines[whole.index]).status == "holds":
            continue
        deciders = ", ".join(robot.names[k] for k in sorted(robot.influence(prop.tables)))
        raise fail(
            "--table",
            N_(
                "--table {name}: property {prop} fails in the robot as it is, and only table "
                "{deciders} decides it, which evolve --table {name} leaves as it is, so no "
                "{name} table could keep it",
                name=whole.name,
                prop=prop.name,
                deciders=deciders,
            ),
            N_(
                "mend table {deciders} first (tablebot check shows the counterexample; evolve --table "
                "repairs the table it evolves), or give --properties files without {prop}",
                deciders=deciders,
                prop=prop.name,
            ),
        )
