"""What the matching rule does with a row that requires no event: one finding per such row, naming the row,
what the table's rule (the robot file's ``match``) does with it, whether the document's rule would differ
there, and the key that chooses."""

from __future__ import annotations

from dataclasses import replace

from tablebot.analysis.finding import Finding
from tablebot.analysis.names import state_text
from tablebot.robot import MATCH_ALWAYS, MATCH_DOCUMENT, Robot, StateId
from tablebot.table import NoEventRow, Row, Table, no_event_rows

CODE = "no-event-row"


def no_event_findings(table: Table) -> list[Finding]:
    """A finding per row that requires no event; a later one of its state is shadowed by the first, and says so."""
    first: dict[StateId, Row] = {}
    findings = []
    for found in no_event_rows(table):
        above = first.setdefault(found.row.state, found.row)
        finding = _finding(table, found)
        if above is not found.row:
            finding = replace(finding, message=f"{finding.message}; but the row on line {above.line} above it "
                              f"requires no event either, so this one never fires in {state_text(table, above.state)}",
                              hint=f"give it an event so that it can fire, or delete it (line {above.line} "
                              "does what it would)")
        findings.append(finding)
    return findings


def _finding(table: Table, found: NoEventRow) -> Finding:
    robot, row = table.robot, found.row
    where = state_text(table, row.state)
    head = f"row on line {row.line} requires no event"
    if not found.quiet:
        return _note(found, f"{head}; in {where} T is there on every tick (the timer is 0 whenever the robot is "
                     f"there), so both matching rules fire it whenever no row above it matches ({_rule(robot)})",
                     "the rule matters only on a tick with no event at all; the robot file's match chooses it")
    quiet = f"in {where} such a tick can come ({found.quiet})"
    if robot.toml is None and robot.match == MATCH_DOCUMENT:  # no robot file: the built-in BumberBot
        return Finding(
            CODE, "warning",
            f"{head}; the table has no robot file, so it runs as the built-in BumberBot, which follows the "
            f'document\'s engine (match = "document"): the row fires only on a tick with some event, never on one '
            f"with no event at all, and {quiet}; earlier versions of tablebot fired the row there",
            (row.line,), 'to fire it on such a tick too, give the table a robot file (NAME.toml beside it, like '
            'examples/bumberbot/robot.toml) with match = "always"', row.state, _detail(robot, found))
    if not robot.says_match:
        return Finding(
            CODE, "warning",
            f"{head}, and {robot.source} does not say which matching rule the table follows: by default "
            f'(match = "always", tablebot\'s rule before it could be chosen) the row fires even on a tick with no '
            f"event at all, and {quiet}; the document's engine looks a row up only if an event is detected, so "
            "there it would do nothing",
            (row.line,), f'write match = "always" (keep this) or match = "document" (as the document\'s engine) '
            f"at the top of {robot.source}", row.state, _detail(robot, found))
    if robot.match == MATCH_ALWAYS:
        return _note(found, f'{head}: with match = "always" ({_key(robot)}) it fires even on a tick with no event '
                     f"at all, and {quiet}; the document's engine looks a row up only if an event is detected, so "
                     "there it would do nothing",
                     'match = "document" makes tablebot do as the document\'s engine; the ROBO Pro lists '
                     "(export --to robopro) are run by that engine and need it")
    return _note(found, f'{head}: with match = "document" ({_key(robot)}) it fires only on a tick with some event '
                 f"(an input that reads 1, T, a counter at 0), as in the document's engine, never on one with no "
                 f"event at all, and {quiet}; then nothing fires", 'match = "always" makes it fire on such a tick too')


def _note(found: NoEventRow, message: str, hint: str) -> Finding:
    return Finding(CODE, "info", message, (found.row.line,), hint, found.row.state,
                   {"quiet": found.quiet})


def _detail(robot: Robot, found: NoEventRow) -> dict[str, str]:
    return {"quiet": found.quiet, "match": robot.match}


def _key(robot: Robot) -> str:
    line = robot.line("", "match")
    return f"{robot.source}:{line}" if line is not None else robot.source


def _rule(robot: Robot) -> str:
    if robot.toml is None:
        return 'the built-in BumberBot has match = "document"'
    if not robot.says_match:
        return f'{robot.source} does not say match; the default is "always"'
    return f'match = "{robot.match}" in {_key(robot)}'
