"""Grading: each submission read against the challenge's robot, its rules proved (through the front door,
:func:`tablebot.api.open` and ``check``), and, if it keeps them all, run on the fleet over the challenge's
scenarios (the same robots for everyone, locally or on Dask), scored by one of evolve's measures: the mean over
the scenarios, summed in scenario order, so that every machine gets the same bits. A submission that fails
anywhere is listed with why, and the others go on."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from tablebot.diagnostics import Diagnostic, TableBotError
from tablebot.grade.challenge import Challenge
from tablebot.grade.several import robot_of
from tablebot.grade.submissions import Submission, confine
from tablebot.i18n import N_, _

if TYPE_CHECKING:
    import numpy as np

    from tablebot.api.project import Project
    from tablebot.fleet.backends import Runner
    from tablebot.fleet.plan import Plan

#: Decimals of a score in scores.csv and on the leaderboard.
DECIMALS = 3


@dataclass(frozen=True)
class Rule:
    """One rule's verdict for one submission: ``status`` holds, violated or unknown; ``story``: what happens
    in its counterexample, tick by tick (empty when it holds)."""

    name: str
    text: str
    status: str
    story: tuple[str, ...] = ()


@dataclass
class Entry:
    """A submission graded: ``why`` is empty when it qualified (then ``values`` has its measure in each
    scenario, in scenario order), else why it scores nothing."""

    sub: Submission
    why: str = ""
    rules: list[Rule] = field(default_factory=list)
    rows: int = 0
    values: np.ndarray | None = None
    plan: Plan | None = None
    project: Project | None = None

    @property
    def name(self) -> str:
        return self.sub.name

    @property
    def score(self) -> float | None:
        return None if self.values is None else float(self.values.sum() / len(self.values))

    @property
    def spread(self) -> float:
        """The standard deviation over the scenarios (0 for one scenario)."""
        import numpy as np

        if self.values is None or len(self.values) < 2:
            return 0.0
        return float(np.std(self.values, ddof=1))


def grade_all(
    challenge: Challenge, subs: list[Submission], runner: Runner, told: Callable[[str], None] = lambda text: None
) -> list[Entry]:
    """Every submission graded, in the order given (one that breaks anything never stops the others)."""
    entries = []
    for sub in subs:
        told(_("grading {name}").format(name=sub.name))
        entry = Entry(sub)
        try:
            if sub.error:
                entry.why = sub.error
            else:
                _grade(challenge, entry, runner)
        except TableBotError as exc:
            entry.why = _words(exc.diagnostics[0], sub)
        except Exception as exc:  # a tablebot bug must not cost the other pupils their grades
            entry.why = f"tablebot could not grade it (a bug in tablebot: {type(exc).__name__}: {exc})"
        if entry.why:
            entry.values = None
        entries.append(entry)
    return entries


def _grade(challenge: Challenge, entry: Entry, runner: Runner) -> None:
    from tablebot.api import open as open_robot

    sub = entry.sub
    assert sub.table is not None  # a submission without a table has its error already
    confine(sub)
    _same_robot(challenge, sub)
    with robot_of(challenge, sub) as (table, robot):  # a robot of several tables: the submission's beside them
        _grade_as(
            challenge,
            entry,
            runner,
            open_robot(
                table,
                robot=robot,
                worlds=challenge.worlds,
                properties=[challenge.properties] if challenge.properties else [],
            ),
            robot,
        )


def _grade_as(challenge: Challenge, entry: Entry, runner: Runner, project: Project, robot: Path) -> None:
    """Prove the submission's rules and, if it keeps them, run it (``robot``: the robot file it runs on)."""
    entry.project, entry.rows = project, len(project.table.rows)
    if challenge.max_rows is not None and entry.rows > challenge.max_rows:
        entry.why = f"{entry.rows} rows, more than the challenge's {challenge.max_rows}"
        return
    check = project.check()
    entry.rules = [
        Rule(p.name, p.text or p.claim, p.status, tuple(check.story(r)) if p.status == "violated" else ())
        for p, r in zip(check.properties, check.results, strict=True)
    ]
    broken = [rule for rule in entry.rules if rule.status != "holds"]
    if broken:
        entry.why = "; ".join(_broken(rule) for rule in broken)
        return
    entry.plan, entry.values = _run(challenge, project, runner, robot)


def _broken(rule: Rule) -> str:
    if rule.status == "violated":
        shows = " / ".join(line.replace("   <- it shows here", " (it shows here)") for line in rule.story[-2:])
        return f"breaks {rule.name} ({rule.text})" + (f": {shows}" if shows else "")
    return f"{rule.name} could not be proved ({rule.text})"


def _same_robot(challenge: Challenge, sub: Submission) -> None:
    """A submission's own robot file must describe the challenge's robot (its name and comments may differ):
    a table written for other inputs, motors, sensors or timing would be graded as another robot."""
    from tablebot.diagnostics import fail
    from tablebot.robot import load_robot

    if sub.robot_file is None:
        return
    mine, theirs = load_robot(sub.robot_file), load_robot(challenge.robot)
    for what in ("inputs", "motors", "counters", "sensors", "tick_ms", "initial_state", "initial_timer", "match"):
        if getattr(mine, what) != getattr(theirs, what):
            raise fail(
                sub.robot_file.name,
                N_(
                    "its robot file is not the challenge's robot: its {what} differ",
                    what=ROBOT_PARTS.get(what, what.replace("_", " ")),
                ),
                N_("write the table for the challenge's robot.toml"),
            )


#: The parts of a robot file a submission must keep as the challenge has them, as a message names them.
ROBOT_PARTS = {"inputs": N_("inputs"), "motors": N_("motors"), "counters": N_("counters"), "sensors": N_("sensors")}


def _run(challenge: Challenge, project: Project, runner: Runner, robot: Path) -> tuple[Plan, np.ndarray]:
    """The table on the fleet over the challenge's scenarios: the score's measure in each one."""
    from tablebot.evolve.evaluate import Evaluator
    from tablebot.fleet.plan import make_plan

    plan = make_plan(
        project.path,
        robot,
        list(challenge.worlds),
        list(challenge.grid),
        challenge.seeds,
        None,
        challenge.seconds,
        every_table=True,
    )  # a robot of several tables runs whole
    got = {}

    def done(key: str, means: dict[str, float], values: dict[str, np.ndarray]) -> None:
        got[key] = values[challenge.score]

    Evaluator(plan, runner, [challenge.score]).run([("submission", plan.table)], done)
    return plan, got["submission"]


def _words(d: Diagnostic, sub: Submission) -> str:
    """A diagnostic with its file named within the submission (never a path of this machine)."""
    where = _relative(d.path, sub)
    place = ":".join([where, *(str(n) for n in (d.line, d.column) if n is not None)])
    return f"{place}: {d.message}" + (f" ({d.hint})" if d.hint else "")


def _relative(path: str, sub: Submission) -> str:
    if sub.own is not None:
        try:
            return Path(path).resolve().relative_to(sub.own.resolve()).as_posix()
        except ValueError:
            pass
    return Path(path).name or path


def ranked(entries: list[Entry], better: str) -> list[tuple[int | None, Entry]]:
    """The entries in leaderboard order with their ranks: the qualified by score (ties share a rank and are
    listed by name), then the others by name, unranked."""
    qualified = [e for e in entries if not e.why]
    sign = 1.0 if better == "low" else -1.0
    qualified.sort(key=lambda e: (sign * round(e.score or 0.0, DECIMALS), e.name))
    out: list[tuple[int | None, Entry]] = []
    for k, entry in enumerate(qualified):
        tied = k and round(entry.score or 0.0, DECIMALS) == round(qualified[k - 1].score or 0.0, DECIMALS)
        out.append((out[-1][0] if tied else k + 1, entry))
    return out + [(None, e) for e in sorted((e for e in entries if e.why), key=lambda e: e.name)]


def best_and_worst(entry: Entry, better: str) -> tuple[int, int]:
    """The scenario indices of the submission's best and worst run (the first among equals)."""
    import numpy as np

    assert entry.values is not None
    values = entry.values if better == "low" else -entry.values
    return int(np.argmin(values)), int(np.argmax(values))


def shown(value: float) -> str:
    """A score as scores.csv and the leaderboard write it."""
    return f"{0.0 if math.isclose(value, 0.0, abs_tol=10 ** -(DECIMALS + 1)) else value:.{DECIMALS}f}"


__all__ = ["DECIMALS", "Entry", "Rule", "best_and_worst", "grade_all", "ranked", "shown"]
