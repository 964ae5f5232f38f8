"""What the matching rule does with a row that requires no event: one finding per such row, naming the row,
what the table's rule (the robot file's ``match``) does with it, whether the document's rule would differ
there, and the key that chooses."""

from __future__ import annotations

from dataclasses import replace

from tablebot.analysis.finding import Finding
from tablebot.analysis.names import state_text
from tablebot.i18n import N_
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
            finding = replace(
                finding,
                message=N_(
                    "{finding}; but the row on line {above} above it requires no event either, so this one never fires "
                    "in {state}",
                    finding=finding.message,
                    above=above.line,
                    state=state_text(table, above.state),
                ),
                hint=N_(
                    "give it an event so that it can fire, or delete it (line {above} does what it would)",
                    above=above.line,
                ),
            )
        findings.append(finding)
    return findings


def _finding(table: Table, found: NoEventRow) -> Finding:
    robot, row = table.robot, found.row
    where = state_text(table, row.state)
    line = row.line
    if not found.quiet:
        return _note(
            found,
            N_(
                "row on line {line} requires no event; in {where} T is there on every tick (the timer "
                "is 0 whenever the robot is there), so both matching rules fire it whenever no row "
                "above it matches ({rule})",
                line=line,
                where=where,
                rule=_rule(robot),
            ),
            N_("the rule matters only on a tick with no event at all; the robot file's match chooses it"),
        )
    quiet = N_("in {where} such a tick can come ({why})", where=where, why=found.quiet)
    if robot.toml is None and robot.match == MATCH_DOCUMENT:  # no robot file: the built-in BumberBot
        return Finding(
            CODE,
            "warning",
            N_(
                "row on line {line} requires no event; the table has no robot file, so it runs as the built-in "
                'BumberBot, which follows the document\'s engine (match = "document"): the row fires only on a tick '
                "with some event, never on one with no event at all, and {quiet}; earlier versions of tablebot fired "
                "the row there",
                line=line,
                quiet=quiet,
            ),
            (row.line,),
            N_(
                "to fire it on such a tick too, give the table a robot file (NAME.toml beside it, like "
                'examples/bumberbot/robot.toml) with match = "always"'
            ),
            row.state,
            _detail(robot, found),
        )
    if not robot.says_match:
        return Finding(
            CODE,
            "warning",
            N_(
                "row on line {line} requires no event, and {source} does not say which matching rule the table "
                'follows: by default (match = "always", tablebot\'s rule before it could be chosen) the row fires '
                "even on a tick with no event at all, and {quiet}; the document's engine looks a row up only if an "
                "event is detected, so there it would do nothing",
                line=line,
                source=robot.source,
                quiet=quiet,
            ),
            (row.line,),
            N_(
                'write match = "always" (keep this) or match = "document" (as the document\'s engine) '
                "at the top of {source}",
                source=robot.source,
            ),
            row.state,
            _detail(robot, found),
        )
    if robot.match == MATCH_ALWAYS:
        return _note(
            found,
            N_(
                'row on line {line} requires no event: with match = "always" ({key}) it fires even '
                "on a tick with no event at all, and {quiet}; the document's engine looks a row up "
                "only if an event is detected, so there it would do nothing",
                line=line,
                key=_key(robot),
                quiet=quiet,
            ),
            N_(
                'match = "document" makes tablebot do as the document\'s engine; the ROBO Pro lists '
                "(export --to robopro) are run by that engine and need it"
            ),
        )
    return _note(
        found,
        N_(
            'row on line {line} requires no event: with match = "document" ({key}) it fires only on '
            "a tick with some event (an input that reads 1, T, a counter at 0), as in the document's "
            "engine, never on one with no event at all, and {quiet}; then nothing fires",
            line=line,
            key=_key(robot),
            quiet=quiet,
        ),
        N_('match = "always" makes it fire on such a tick too'),
    )


def _note(found: NoEventRow, message: str, hint: str) -> Finding:
    return Finding(CODE, "info", message, (found.row.line,), hint, found.row.state, {"quiet": found.quiet})


def _detail(robot: Robot, found: NoEventRow) -> dict[str, str]:
    return {"quiet": found.quiet, "match": robot.match}


def _key(robot: Robot) -> str:
    line = robot.line("", "match")
    return f"{robot.source}:{line}" if line is not None else robot.source


def _rule(robot: Robot) -> str:
    if robot.toml is None:
        return N_('the built-in BumberBot has match = "document"')
    if not robot.says_match:
        return N_('{source} does not say match; the default is "always"', source=robot.source)
    return N_('match = "{match}" in {key}', match=robot.match, key=_key(robot))
