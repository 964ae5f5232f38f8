"""The robot file's ``[properties]``: kept as written when the file is read, checked against the table when
``tablebot check`` reads them (:mod:`tablebot.analysis.properties`)."""

from __future__ import annotations

from typing import Any

from tablebot.robot import Robot, register_section
from tablebot.tomlfile import Source


def read_section(src: Source, entries: Any, robot: Robot) -> Any:
    return entries


register_section("properties", read_section)
