"""``check`` from Python: the table's findings and its properties proved, as :class:`Check`."""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass, fields
from pathlib import Path
from typing import TYPE_CHECKING, Any

from tablebot.diagnostics import fail
from tablebot.i18n import N_

if TYPE_CHECKING:
    from tablebot.analysis.check import CheckReport
    from tablebot.analysis.finding import Finding
    from tablebot.analysis.prove import Result
    from tablebot.api.progress import Progress
    from tablebot.loading import Loaded, PathLike


@dataclass(frozen=True)
class PropertyResult:
    """One property and what proving it gave, with the names and values of ``check --format json``:
    ``status`` is ``holds``, ``violated`` or ``unknown``; a counterexample (or a ``reachable`` property's
    example) has ``ticks``, the tick it shows at and whether it is the ``shortest``, and ``inputs_csv`` once
    :meth:`Check.write_counterexamples` has written it.

    >>> import tablebot
    >>> first = tablebot.open("examples/bumberbot").check().properties[0]
    >>> first.name, first.status, first.level
    ('collision_stops', 'holds', 'error')
    """

    name: str
    text: str
    claim: str
    status: str
    level: str
    note: str
    source: str
    line: int | None
    situations_explored: int
    inputs_csv: str | None = None
    ticks: int | None = None
    shows_at_tick: int | None = None
    shortest: bool | None = None
    trapped_in_state: Any = None
    detail: str | None = None

    @classmethod
    def of(cls, data: dict[str, Any]) -> PropertyResult:
        return cls(**{f.name: data[f.name] for f in fields(cls) if f.name in data})


@dataclass(frozen=True)
class Check:
    """What ``check`` found: :attr:`findings` (each a :class:`~tablebot.analysis.finding.Finding`: ``code``,
    ``severity``, ``message``, ``lines``, ``hint``) and :attr:`properties`; :attr:`ok` when nothing is an
    error (the command's exit code 0). :meth:`json_text` is what ``check --format json`` prints.

    >>> import tablebot
    >>> report = tablebot.open("examples/bumberbot").check()
    >>> report.ok, [p.status for p in report.properties[:2]]
    (True, ['holds', 'holds'])
    """

    report: CheckReport

    @property
    def findings(self) -> list[Finding]:
        return self.report.findings

    @property
    def properties(self) -> list[PropertyResult]:
        return [PropertyResult.of(p) for p in self.json()["properties"]]

    @property
    def results(self) -> list[Result]:
        """The prover's own results, in the order of :attr:`properties` (for :meth:`story`)."""
        return self.report.results

    @property
    def counts(self) -> dict[str, int]:
        """Errors, warnings and notes (``info``), a violated property counted at its level."""
        return self.report.counts()

    @property
    def ok(self) -> bool:
        return self.exit_code() == 0

    def exit_code(self, strict: bool = False) -> int:
        """0 clean, 1 for warnings when ``strict``, 2 for errors: the command's exit code."""
        return self.report.exit_code(strict)

    def json(self, strict: bool = False) -> dict[str, Any]:
        """The report as ``check --format json`` gives it (``strict``: its ``--strict``)."""
        from tablebot.analysis.check import report_json

        return report_json(self.report, strict)

    def json_text(self, strict: bool = False) -> str:
        """:meth:`json` as the command prints it, byte for byte."""
        return json.dumps(self.json(strict), indent=2) + "\n"

    def write_counterexamples(self, folder: PathLike) -> list[Path]:
        """Each counterexample (and ``reachable`` example) as ``folder/NAME.csv``, all at once (``check
        --counterexamples``; replay one with ``tablebot trace TABLE --inputs FILE``)."""
        from tablebot.analysis.check import write_counterexamples
        from tablebot.files import out_folder

        if not any(r.inputs for r in self.report.results):
            return []
        write_counterexamples(self.report, out_folder(Path(folder), "--counterexamples"))
        return list(self.report.counterexamples.values())

    def story(self, result: Result) -> list[str]:
        """What happens in a property's counterexample, tick by tick (quiet stretches folded)."""
        from tablebot.analysis.check import story
        from tablebot.analysis.check_tables import story_of_tables

        if self.report.tables is not None:  # a robot of several tables: each table's line, each tick
            return story_of_tables(self.report.tables, result)
        return story(self.report.machine, result)


def check(project: Loaded, *, targets: Sequence[str] = (), progress: Progress | None = None) -> Check:
    """Explore the table, list what can go wrong in it and prove its properties (the robot file's
    ``[properties]`` and :attr:`~tablebot.api.project.Project.property_files`); ``targets`` are export
    targets whose limits to check too (``check --target``)."""
    from tablebot import registry
    from tablebot.api.progress import Progress

    shown = progress or Progress()
    known = registry.check_targets()
    for name in targets:
        if name not in known:
            raise fail(
                "--target",
                N_("unknown export target {name!r}", name=name),
                N_("use one of {known}", known=tuple(known)),
            )
    props = project.properties()
    shown.start("steps", 3 + len(props), done=1)  # reading is done; exploring, findings, then each property
    try:
        return Check(project.check_report(targets, shown.step, props))
    finally:
        shown.stop()
