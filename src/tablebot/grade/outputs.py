"""What ``grade`` writes: ``scores.csv`` (rank, name, score, why: the same bytes on every machine) and
``leaderboard.html``, one page with nothing to fetch: rank, name, score with its spread, every rule's verdict
with its counterexample's words, and each qualified submission's best and worst run, replayed in the page
itself. Each replay is the page ``tablebot sim --html`` writes (:mod:`tablebot.web.replay`), compressed
(zlib) into the leaderboard and unpacked by the browser (DecompressionStream) when it is asked for: about
80 KB a run instead of 430."""

from __future__ import annotations

import csv
import io
from pathlib import Path

from tablebot.escape import html_text as h
from tablebot.grade.challenge import Challenge
from tablebot.grade.run import Entry, best_and_worst, ranked, shown
from tablebot.i18n import _, current, localise, ngettext

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


Replays = dict[str, list[tuple[str, str]]]  # per submission name: (label, key of its packed page)


def replay_pages(entries: list[Entry], challenge: Challenge) -> tuple[Replays, dict[str, str]]:
    """Each qualified submission's best and worst run as a replay page, packed: the labels per name, and
    each page's zlib-compressed bytes in base64 by key (``NNN-best``: by place on the board, never by a
    pupil's text)."""
    import base64
    import zlib

    from tablebot.fleet.spec import runs
    from tablebot.web.replay import render_html, replay_data

    links: Replays = {}
    packed: dict[str, str] = {}
    for k, (_rank, entry) in enumerate(ranked(entries, challenge.better)):
        if entry.why or entry.plan is None or entry.values is None:
            continue
        plan = entry.plan
        for which, index in zip(("best", "worst"), best_and_worst(entry, challenge.better), strict=True):
            run = runs(plan.spec, index, index + 1)[0]
            label = (
                _("best: seed {seed}, {measure} {value}")
                if which == "best"
                else _("worst: seed {seed}, {measure} {value}")
            ).format(seed=run.seed, measure=challenge.score, value=shown(float(entry.values[index])))
            data = replay_data(
                plan.traced(index).trace_lines(0),
                plan.worlds[run.world],
                plan.table,
                plan.scenes[run.world].params,
                f"{entry.name}: {label}",
            )
            key = f"{k + 1:03d}-{which}"
            packed[key] = base64.b64encode(zlib.compress(render_html(data).encode("utf-8"), 9)).decode("ascii")
            links.setdefault(entry.name, []).append((label, key))
    return links, packed


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
button.replay { font: inherit; font-size: .9rem; margin: .1rem 0; padding: .3rem .6rem; min-height: 2.5rem;
  border: 1px solid #1e6fd9; border-radius: 4px; background: #fff; color: #1e6fd9; cursor: pointer; display: block; }
#viewer { position: fixed; inset: 0; background: rgba(30, 39, 46, .6); display: flex; flex-direction: column;
  padding: 1rem; } #viewer[hidden] { display: none; }
#viewer .head { display: flex; justify-content: flex-end; } #viewer iframe { flex: 1; border: 0; background: #fff; }
#viewer .head button { font: inherit; min-height: 2.5rem; padding: .3rem 1rem; }
"""

#: Opens a replay: its page unpacked from the script element that holds it, shown in a frame over the board.
SCRIPT = """
const viewer = document.getElementById('viewer');
const frame = viewer.querySelector('iframe');
async function unpack(key) {
  const text = document.getElementById('replay-' + key).textContent;
  const bytes = Uint8Array.from(atob(text), (c) => c.charCodeAt(0));
  const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream('deflate'));
  return new Response(stream).text();
}
function close() { viewer.hidden = true; frame.removeAttribute('srcdoc'); }
document.addEventListener('click', async (event) => {
  const button = event.target.closest('button.replay');
  if (button) { frame.srcdoc = await unpack(button.dataset.replay); viewer.hidden = false; frame.focus(); }
});
viewer.querySelector('.head button').addEventListener('click', close);
function onEscape(event) { if (event.key === 'Escape') close(); }
document.addEventListener('keydown', onEscape);
frame.addEventListener('load', () => {  // Esc pressed in the replay, too (its page has the board's origin)
  if (frame.contentDocument) frame.contentDocument.addEventListener('keydown', onEscape);
});
"""


def leaderboard_html(entries: list[Entry], challenge: Challenge, replays: Replays, packed: dict[str, str]) -> str:
    """The page: a row per submission in leaderboard order, the packed replays, the viewer."""
    rows = "".join(_row(rank, entry, replays.get(entry.name, [])) for rank, entry in ranked(entries, challenge.better))
    pages = "".join(f'<script type="text/plain" id="replay-{key}">{text}</script>' for key, text in packed.items())
    replay, close = h(_("replay")), h(_("close (Esc)"))
    viewer = (
        f'<div id="viewer" hidden role="dialog" aria-label="{replay}"><div class="head"><button type="button">'
        f'{close}</button></div><iframe title="{replay}"></iframe></div>'
    )
    page_title = h(_("{title}: leaderboard").format(title=challenge.title))
    heads = "".join(f"<th>{h(head)}</th>" for head in (_("rank"), _("name"), _("score"), _("rules"), _("replays")))
    return (
        f'<!DOCTYPE html>\n<html lang="{current() if current() != "pseudo" else "en"}"><head><meta charset="utf-8">'
        f'<meta name="viewport" content="width=device-width, initial-scale=1">'
        f"<title>{page_title}</title><style>{STYLE}</style>"
        f'</head><body><h1>{h(challenge.title)}</h1><p class="about">{h(_about(entries, challenge))}</p>'
        f"<table><thead><tr>{heads}</tr></thead>"
        f"<tbody>{rows}</tbody></table>{viewer}{pages}<script>{SCRIPT}</script></body></html>\n"
    )


def _about(entries: list[Entry], challenge: Challenge) -> str:
    """The line under the title: what was run, how it is scored, in the reader's language."""
    from tablebot.fleet.spec import parse_seeds

    planned = [e.plan.spec.total for e in entries if e.plan is not None]  # seeds x grid values x worlds
    scenarios = planned[0] if planned else len(parse_seeds(challenge.seeds, None)) * len(challenge.worlds)
    ran = ngettext(
        "{n} submission, run on {scenarios} scenarios of {seconds:g} s; ",
        "{n} submissions, each run on the same {scenarios} scenarios of {seconds:g} s; ",
        len(entries),
    )
    scored = (
        _(
            "score: {measure} (low is better), the mean over the scenarios ± its standard deviation. A table "
            "that breaks a rule scores nothing."
        )
        if challenge.better == "low"
        else _(
            "score: {measure} (high is better), the mean over the scenarios ± its standard deviation. A table "
            "that breaks a rule scores nothing."
        )
    )
    return ran.format(n=len(entries), scenarios=scenarios, seconds=challenge.seconds) + scored.format(
        measure=challenge.score
    )


def _row(rank: int | None, entry: Entry, replays: list[tuple[str, str]]) -> str:
    if entry.why or entry.values is None or entry.score is None:
        score = '<span class="out">' + h(_("no score")) + "</span>"
    else:
        low, high = float(entry.values.min()), float(entry.values.max())
        score = (
            f'{shown(entry.score)}<span class="spread">± {shown(entry.spread)} '
            + h(_("({low} to {high})").format(low=shown(low), high=shown(high)))
            + "</span>"
        )
    links = "".join(
        f'<button type="button" class="replay" data-replay="{h(key)}">▶ {h(label)}</button>' for label, key in replays
    )
    klass = "" if rank is not None else ' class="unranked"'
    given = Path(entry.sub.given).name if Path(entry.sub.given).exists() else entry.sub.given  # no machine's paths
    source = f'<br><small class="out">{h(given)}</small>' if given != entry.name else ""
    return (
        f'<tr{klass}><td class="rank">{"" if rank is None else rank}</td><td>{h(entry.name)}{source}'
        f'</td><td class="score">{score}</td>'
        f"<td>{_rules(entry)}</td><td>{links}</td></tr>"
    )


def _rules(entry: Entry) -> str:
    parts = []
    for rule in entry.rules:
        if rule.status == "holds":
            parts.append(f'<div class="holds">✓ {h(rule.name)}</div>')
            continue
        verdict = h(_("breaks") if rule.status == "violated" else _("not proved:"))
        story = "\n".join(str(localise(line)) for line in rule.story)  # Messages: in the reader's language
        parts.append(
            f'<details open><summary class="broken">✗ {verdict} {h(rule.name)}</summary>'
            f"{h(rule.text)}" + (f"<pre>{h(story)}</pre>" if story else "") + "</details>"
        )
    if entry.why and not any(rule.status != "holds" for rule in entry.rules):
        parts.append(f'<div class="broken">{h(entry.why)}</div>')
    return "".join(parts)
