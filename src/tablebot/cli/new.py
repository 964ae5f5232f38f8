"""The ``new`` command: a ready folder (table, robot file, world, properties) to start a robot of your own."""

from __future__ import annotations

from enum import StrEnum
from pathlib import Path

import typer

from tablebot.cli.app import app
from tablebot.cli.common import console, guarded
from tablebot.diagnostics import severity_word
from tablebot.escape import shell_word, terminal
from tablebot.i18n import N_, _, asked, localise
from tablebot.i18n.headers import header_line


class From(StrEnum):
    bumberbot = "bumberbot"
    line_follower = "line-follower"
    obstacle_avoider = "obstacle-avoider"
    empty = "empty"


@app.command("new")
@guarded
def new_cmd(
    folder: Path = typer.Argument(..., metavar="FOLDER", help="The folder to create (it must not exist, or be empty)."),
    template: From = typer.Option(From.empty, "--from", help="Start from a shipped example, or from an empty robot."),
    inputs: list[str] = typer.Option(
        [],
        "--inputs",
        help="Your input names, comma separated, each optionally "
        'NAME=label (I1,I2 or "I1=left bumper"); with --from an example, they '
        "rename its inputs in order.",
    ),
    motors: list[str] = typer.Option(
        [],
        "--motors",
        help="Your motor names, the same way (the first two drive the right and left wheel in the simulator).",
    ),
) -> None:
    """Create FOLDER with a table, its robot file, a world and properties: ready for check, sim and tests."""
    from tablebot import templates

    made = templates.make(
        template.value,
        folder.name or "robot",
        templates.parse_names(inputs, "--inputs"),
        templates.parse_names(motors, "--motors"),
    )
    made.files["table.csv"] = header_line(made.files["table.csv"], asked())  # Zustand, Folgezustand with --lang de
    written = templates.write_folder(folder, made)
    source = N_("an empty robot") if template is From.empty else N_("the {name} example", name=template.value)
    console.print(_("created {folder} from {source}:").format(folder=terminal(str(folder)), source=localise(source)))
    for path in written:
        console.print(f"  {terminal(str(path)):<36} {terminal(localise(templates.PURPOSE[path.name]))}")
    for note in made.notes:
        console.print(f"[yellow]{severity_word('note')}:[/yellow] {terminal(localise(note))}")
    console.print(_("next:"))
    for command in ("check", "sim", "diagram"):  # lines to paste: the folder quoted for a shell
        console.print(f"  tablebot {command} {terminal(shell_word(str(folder)))}")
