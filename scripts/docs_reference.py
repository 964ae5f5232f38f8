"""Write the reference pages that are made from the code, so that they cannot drift from it:
docs/commands.md (every command and option, from the command line's own definitions, as `-h` shows them)
and docs/sim-parameters.md (every simulator parameter with its default, range and source).

    .venv/bin/python scripts/docs_reference.py           # write both pages
    .venv/bin/python scripts/docs_reference.py --check   # exit 1 naming the pages that are out of date

`make docs` (mkdocs, through scripts/docs_hooks.py) and tests/project/test_docs_reference.py fail while a page is
out of date.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path
from typing import Any

import typer.main

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
GENERATED = "<!-- Made by scripts/docs_reference.py from the code: do not edit; run the script again. -->\n"


def _text(value: str) -> str:
    """Help text as Markdown that shows it literally: no HTML, emphasis or table cells made of it."""
    value = value.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
    value = re.sub(r"([\\`*_|\[\]])", r"\\\1", value)
    return " ".join(value.split())


def _code(value: str) -> str:
    """A name or metavar as inline code inside a table cell."""
    return "`" + value.replace("|", "\\|") + "`"


def _paragraphs(help_text: str) -> str:
    parts = [" ".join(p.split()) for p in re.split(r"\n\s*\n", help_text.strip()) if p.strip()]
    return "\n\n".join(_text(p) for p in parts)


def _params_table(command: Any, ctx: Any) -> list[str]:
    rows = []
    for param in command.get_params(ctx):
        if getattr(param, "hidden", False):
            continue
        record = param.get_help_record(ctx)
        if record is None:
            continue
        name, what = record
        rows.append(f"| {_code(name)} | {_text(what)} |")
    if not rows:
        return []
    return ["| argument or option | what it does |", "|---|---|", *rows, ""]


def _context(command: Any, name: str, parent: Any) -> Any:
    """The context `-h` would see (typer builds its commands on a click of its own: its classes are used)."""
    return command.context_class(command, info_name=name, parent=parent, **command.context_settings)


def commands_page() -> str:
    """docs/commands.md: the top level's options, then each command in `tablebot -h`'s order."""
    from tablebot.cli import app

    group: Any = typer.main.get_command(app)  # a group: typer builds it on a click of its own
    top = _context(group, "tablebot", None)
    lines = [
        GENERATED,
        "# Commands and options",
        "",
        "Every command of `tablebot` with every argument and option, as `tablebot COMMAND -h` prints them. "
        "`-h` and `--help` work everywhere.",
        "",
        "```",
        group.get_usage(top),
        "```",
        "",
        *_params_table(group, top),
    ]
    lines += ["| command | what it does |", "|---|---|"]
    names = list(group.commands)
    for name in names:
        command = group.commands[name]
        lines.append(f"| [`{name}`](#{name}) | {_text(command.get_short_help_str(limit=100))} |")
    lines.append("")
    for name in names:
        command = group.commands[name]
        ctx = _context(command, name, top)
        lines += [
            f"## `tablebot {name}` {{#{name}}}",
            "",
            _paragraphs(command.help or ""),
            "",
            "```",
            command.get_usage(ctx),
            "```",
            "",
            *_params_table(command, ctx),
        ]
    return "\n".join(lines).rstrip() + "\n"


def sim_parameters_page() -> str:
    """docs/sim-parameters.md: every ``[sim.SECTION]`` key of a robot file (and world file section)."""
    from tablebot.sim.model.params import DEFAULTS, WIRING

    lines = [
        GENERATED,
        "# Simulator parameters",
        "",
        "The simulated robot's physical parameters. Each has a default, fitted to the BumberBot; a robot file "
        "changes one in a section `[sim.SECTION]` (`[sim.motor]` `friction_volts = 0.4`), a world file in a "
        "section `[SECTION]` of its own, which wins over the robot file's. A value outside its range is an "
        "error naming the file and line. Where a number comes from is said beside it (*estimate* where no "
        "source gives it). `tablebot sweep --grid SECTION.KEY=V1,V2` runs a robot over several values.",
        "",
    ]
    for section, keys in DEFAULTS.items():
        lines += [
            f"## `[sim.{section}]`",
            "",
            "| key | default | range | what it is, and its source |",
            "|---|---|---|---|",
        ]
        for key, (default, low, high, what) in keys.items():
            lines.append(f"| `{key}` | {default:g} | {low:g} … {high:g} | {_text(what)} |")
        lines.append("")
    lines += [
        "## `[sim.wiring]`",
        "",
        "Which of the robot's inputs and motors play the simulated BumberBot's parts (an input declared in "
        "`[sensors]` is read as that sensor instead, and cannot be wired to a part here).",
        "",
        "| key | default |",
        "|---|---|",
        *[f"| `{role}` | `{name}` |" for role, name in WIRING.items()],
        "",
    ]
    return "\n".join(lines).rstrip() + "\n"


PAGES = {"commands.md": commands_page, "sim-parameters.md": sim_parameters_page}


def made(name: str) -> str:
    """Page ``name`` as the code makes it now, in English whatever the process speaks (the German site translates
    the pages; a test run whose earlier test left the process speaking German found the page out of date)."""
    from tablebot.i18n import speaking

    with speaking("en"):
        return PAGES[name]()


def stale() -> list[str]:
    """The generated pages whose file differs from what the code makes now."""
    out = []
    for name in PAGES:
        path = DOCS / name
        if not path.exists() or path.read_text(encoding="utf-8") != made(name):
            out.append(name)
    return out


def write() -> None:
    for name in PAGES:
        path = DOCS / name
        tmp = path.with_name(f".{name}.tmp")
        tmp.write_text(made(name), encoding="utf-8")
        tmp.replace(path)


if __name__ == "__main__":
    if sys.argv[1:] == ["--check"]:
        old = stale()
        if old:
            print(
                f"out of date: {', '.join('docs/' + n for n in old)}; run .venv/bin/python scripts/docs_reference.py",
                file=sys.stderr,
            )
        sys.exit(1 if old else 0)
    write()
