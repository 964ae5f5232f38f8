"""A finding: one thing ``tablebot check`` tells the author, with its severity and file lines."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from tablebot.robot import StateId

SEVERITIES = ("error", "warning", "info")


@dataclass(frozen=True)
class Finding:
    """One thing worth telling the author, at the rows (file lines) it is about."""

    code: str
    severity: str
    message: str
    lines: tuple[int, ...] = ()
    hint: str = ""
    state: StateId | None = None
    detail: dict[str, Any] = field(default_factory=dict, compare=False)
    #: In a robot of several tables, a finding of another table than the main one: its name and file.
    table: str = ""
    path: str = ""

    def as_json(self) -> dict[str, Any]:
        where = {"table": self.table, "file": self.path} if self.table else {}
        return {
            "code": self.code,
            "severity": self.severity,
            "lines": list(self.lines),
            "state": self.state,
            "message": self.message,
            "hint": self.hint,
            **where,
            **self.detail,
        }
