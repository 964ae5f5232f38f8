"""What ``grade`` writes: ``scores.csv`` (rank, name, score, why: the same bytes on every machine) and
``leaderboard.html``, a page with nothing to fetch (its style inline): rank, name, score with its spread, every
rule's verdict with its counterexample's words, and links to each qualified submission's best and worst run,
each a replay page of its own (``replays/``, made by the replay page builder of ``tablebot sim --html``)."""

from __future__ import annotations

import csv
import io
from pathlib import Path

from tablebot.escape import html_text as h
from tablebot.grade.challenge import Challenge
from tablebot.grade.run import Entry, best_and_worst, ranked, shown

COLUMNS = ("rank", "name", "score", "why")


def scores_csv(entries: list[Entry], challenge: Challenge) -> str:
    """One row per submission in leaderboard order; ``score`` empty when it does not qualify."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(COLUMNS)
    for rank, entry in ranked(entries, challenge.better):
        score = "" if entry.score is None or entry.why else shown(entry.score)
        writer.writerow(["" if rank is None else rank, entry.name, score, entry.why])
    return buffer.getvalue()


def replay_name(rank_index: int, which: str) -> str:
    """A replay page's file name: by place on the board, never by a pupil's text."""
    return f"replays/{rank_index + 1:03d}-{which}.html"


def write_replays(entries: list[Entry], challenge: Challenge, folder: Path) -> dict[str, list[tuple[str, str]]]:
    """Each qualified submission's best and worst run as a replay page; per name, (label, file) pairs."""
    from tablebot.fleet.spec import runs
    from tablebot.web.replay import write_html

    links: dict[str, list[tuple[str, str]]] = {}
    for k, (_, entry) in enumerate(ranked(entries, challenge.better)):
        if entry.why or entry.plan is None or entry.values is None:
            continue
        plan = entry.plan
        pages = []
        for which, index in zip(("best", "worst"), best_and_worst(entry, challenge.better), strict=True):
            run = runs(plan.spec, index, index + 1)[0]
            lines = plan.traced(index).trace_lines(0)
            label = f"{which}: seed {run.seed}, {challenge.score} {shown(float(entry.values[index]))}"
            name = replay_name(k, which)
            write_html(folder / name, lines, plan.worlds[run.world], plan.table, params=plan.scenes[run.world].params,
                       title=f"{entry.name}: {label}")
            pages.append((label, name))
        links[entry.name] = pages
    return links


STYLE = """
body { font: 16px/1.4 system-ui, sans-serif; margin: 1.5rem; color: #1e272e; }
h1 { font-size: 1.6rem; margin: 0 0 .3rem; } p.about { color: #57606f; margin: 0 0 1rem; }
table { border-collapse: collapse; width: 100%; } th, td { border-bottom: 1px solid #dfe4ea; padding: .45rem .6rem;
  text-align: left; vertical-align: top; } th { background: #f1f2f6; position: sticky; top: 0; }
td.rank { font-size: 1.3rem; font-weight: 700; width: 3rem; } td.score { white-space: nowrap; font-weight: 600; }
.spread { color: #57606f; font-weight: 400; font-size: .9rem; display: block; }
.holds { color: #218c5a; } .broken { color: #c0392b; font-weight: 600; } .out { color: #57606f; }
details { margin: .15rem 0; } summary { cursor: pointer; } pre { white-space: pre-wrap; font-size: .85rem;
  background: #f7f7f9; padding: .4rem; margin: .3rem 0; } a { color: #1e6fd9; }
tr.unranked td { background: #fcfcfd; }
"""


def leaderboard_html(entries: list[Entry], challenge: Challenge, replays: dict[str, list[tuple[str, str]]]) -> str:
    """The page: a row per submission in leaderboard order."""
    rows = "".join(_row(rank, entry, replays.get(entry.name, [])) for rank, entry in ranked(entries, challenge.better))
    from tablebot.fleet.spec import parse_seeds

    planned = [e.plan.spec.total for e in entries if e.plan is not None]  # seeds x grid values x worlds
    scenarios = planned[0] if planned else len(parse_seeds(challenge.seeds, None)) * len(challenge.worlds)
    about = (f"{len(entries)} submissions, each run on the same {scenarios} scenarios of {challenge.seconds:g} s; "
             f"score: {challenge.score} ({challenge.better} is better), the mean over the scenarios ± its standard "
             "deviation. A table that breaks a rule scores nothing.")
    return (f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
            f'<meta name="viewport" content="width=device-width, initial-scale=1">'
            f"<title>{h(challenge.title)}: leaderboard</title><style>{STYLE}</style></head><body>"
            f"<h1>{h(challenge.title)}</h1><p class=\"about\">{h(about)}</p>"
            "<table><thead><tr><th>rank</th><th>name</th><th>score</th><th>rules</th><th>replays</th></tr></thead>"
            f"<tbody>{rows}</tbody></table></body></html>\n")


def _row(rank: int | None, entry: Entry, replays: list[tuple[str, str]]) -> str:
    if entry.why or entry.values is None or entry.score is None:
        score = '<span class="out">no score</span>'
    else:
        low, high = float(entry.values.min()), float(entry.values.max())
        score = (f"{shown(entry.score)}<span class=\"spread\">± {shown(entry.spread)} "
                 f"({shown(low)} to {shown(high)})</span>")
    links = " ".join(f'<a href="{h(name)}">{h(label)}</a><br>' for label, name in replays)
    klass = "" if rank is not None else ' class="unranked"'
    given = Path(entry.sub.given).name if Path(entry.sub.given).exists() else entry.sub.given  # no machine's paths
    source = f"<br><small class=\"out\">{h(given)}</small>" if given != entry.name else ""
    return (f"<tr{klass}><td class=\"rank\">{'' if rank is None else rank}</td><td>{h(entry.name)}{source}"
            f"</td><td class=\"score\">{score}</td>"
            f"<td>{_rules(entry)}</td><td>{links}</td></tr>")


def _rules(entry: Entry) -> str:
    parts = []
    for rule in entry.rules:
        if rule.status == "holds":
            parts.append(f'<div class="holds">✓ {h(rule.name)}</div>')
            continue
        verdict = "breaks" if rule.status == "violated" else "not proved:"
        story = "\n".join(rule.story)
        parts.append(f'<details open><summary class="broken">✗ {verdict} {h(rule.name)}</summary>'
                     f"{h(rule.text)}" + (f"<pre>{h(story)}</pre>" if story else "") + "</details>")
    if entry.why and not any(rule.status != "holds" for rule in entry.rules):
        parts.append(f'<div class="broken">{h(entry.why)}</div>')
    return "".join(parts)
