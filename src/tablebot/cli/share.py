"""The ``share`` command: a link that carries a table, its robot file and its world (:mod:`tablebot.share`),
printed for a chat or an e-mail, and its QR code for a phone or a projector."""

from __future__ import annotations

from pathlib import Path

import typer

from tablebot.cli.app import app
from tablebot.cli.common import err_console, guarded, out_file
from tablebot.escape import plain
from tablebot.i18n import N_, _

QR_SCALE = 8  # pixels per module: a QR code of a thousand characters is about 600 px wide, easy for a phone
QR_OPT = typer.Option(None, "--qr", metavar="FILE.png", help="Also write the link's QR code as a PNG picture.")


@app.command("share")
@guarded
def share_cmd(
    where: Path = typer.Argument(..., metavar="FOLDER|TABLE", help="A folder holding table.csv, or a table file."),
    qr: Path | None = QR_OPT,
    base: str = typer.Option(
        "",
        "--base",
        metavar="URL",
        help="The studio address the link starts with "
        "(default: http://127.0.0.1:8765/, where `tablebot studio` serves).",
    ),
) -> None:
    """Print a link that carries FOLDER's table, its robot file and its world, compressed into the part after
    '#' (a browser never sends that to any server). The studio (its Open box, or studio --open LINK) and
    `tablebot grade` read it back; files that are copies of tablebot's shipped examples are named, not carried."""
    from tablebot import share

    if qr is not None:
        out_file(qr, "--qr")  # a picture that cannot be written is said before the link is printed
    shared = share.collect(where)
    link = share.encode(shared, base or share.STUDIO)
    print(link)
    robot = plain(shared.robot[0]) if shared.robot else _("the built-in BumberBot")
    world = _("its world") if shared.world is not None else _("an empty room")
    if shared.tables:  # a robot of several tables: every one of them
        names = plain(", ".join([shared.table[0], *(name for name, _ in shared.tables)]))
        said = _("{n:,} characters: the tables {tables}, {robot}, {world}").format(
            n=len(link), tables=names, robot=robot, world=world
        )
    else:
        said = _("{n:,} characters: the table {table}, {robot}, {world}").format(
            n=len(link), table=plain(shared.table[0]), robot=robot, world=world
        )
    err_console.print(said, markup=False)
    if qr is not None:
        write_qr(qr, link)
        err_console.print(_("wrote {path}").format(path=plain(str(qr))), markup=False)


def write_qr(path: Path, link: str) -> None:
    """The link's QR code as a PNG (the strongest error correction the link leaves room for)."""
    import io

    import segno

    from tablebot.diagnostics import fail
    from tablebot.files import write_bytes

    try:
        code = segno.make(link, error="l", boost_error=True, micro=False)
    except segno.DataOverflowError:
        raise fail(
            "--qr",
            N_("the link is too long for a QR code ({n:,} characters; one holds about 2,900)", n=len(link)),
            N_("share the link as text, or shorten the robot and world files' comments"),
        ) from None
    picture = io.BytesIO()
    code.save(picture, kind="png", scale=QR_SCALE, border=4)
    write_bytes(path, picture.getvalue())
