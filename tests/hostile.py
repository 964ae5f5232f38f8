"""A project whose every free text is hostile: each exporter must keep these texts inert (issue 14)."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

#: A function that would run at boot if the robot name escaped its C comment (the reproduced injection).
EVIL_SYMBOL = "tb_evil_boot"
#: Texts that end comments, strings, tags, labels and shell words, or drive a terminal.
HOSTILE = (
    f"*/ __attribute__((constructor)) static void {EVIL_SYMBOL}(void) {{ }} /*",
    '"\n#include "/etc/hostname"\n',
    "</init><evil/><![CDATA[x]]> & <b>bold</b> \"q\" 'a'",
    "trail\\",
    "??/ trigraph ???/",
    "$(touch pwned) `id`; rm -rf ~ | cat > x & ${HOME}",
    "[bold]markup[/bold] :x: [/]",
    "a;b:c#d%%e #quot; direction LR",
    "\x1b[31mred\x07\x00nul",
    "ünïcødé ✓ \U0001f916",
)
#: Words that must not appear outside a comment/string in any output: evidence of an injection.
INJECTED = (EVIL_SYMBOL, "/etc/hostname", "<evil", "touch pwned")
STATES = ("seek", "back off.left", "_ünï-2")


def toml_str(text: str) -> str:
    """A TOML basic string (JSON's escapes are TOML's, given no surrogate pairs)."""
    return json.dumps(text, ensure_ascii=False)


def robot_toml(name: str = HOSTILE[0]) -> str:
    labels = dict(zip(("I3", "I4", "I5", "I7", "I8"), HOSTILE[1:6], strict=True))
    lines = [f"name = {toml_str(name)}", 'initial_state = "seek"', "[inputs]"]
    lines += [f"{key} = {toml_str(text)}" for key, text in labels.items()]
    lines += ["[motors]", f"M1 = {toml_str('right ' + HOSTILE[6])}", f"M2 = {toml_str('left ' + HOSTILE[7])}"]
    lines += [
        "[states]",
        *(f"{toml_str(s)} = {toml_str(HOSTILE[(i + 8) % len(HOSTILE)])}" for i, s in enumerate(STATES)),
    ]
    return "\n".join(lines) + "\n"


def table_csv() -> str:
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(["description", "state", "T", "I3", "I4", "I5", "I7", "I8", "M1", "M2", "timer", "next"])
    for i, text in enumerate(HOSTILE):
        state, nxt = STATES[i % len(STATES)], STATES[(i + 1) % len(STATES)]
        events = [""] * 6
        events[i % 6] = "1"
        writer.writerow([text, state, *events, str(i % 5 - 2), str(2 - i % 5), str(10 * i), nxt])
    return buffer.getvalue()


def properties_toml() -> str:
    lines = []
    for i, text in enumerate(HOSTILE):
        lines += [
            f"[prop_{i}]",
            f"text = {toml_str(text)}",
            f"note = {toml_str(text)}",
            f"reachable = {toml_str('state == seek')}" if i % 2 else 'never = "M1 > 5"',
            "",
        ]
    return "\n".join(lines)


def write_project(folder: Path) -> Path:
    """table.csv, robot.toml and properties.toml in ``folder`` (made); returns the table path."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "robot.toml").write_text(robot_toml(), encoding="utf-8")
    (folder / "properties.toml").write_text(properties_toml(), encoding="utf-8")
    table = folder / "table.csv"
    table.write_text(table_csv(), encoding="utf-8")
    return table
