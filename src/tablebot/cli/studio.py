"""The ``studio`` command: the table, the live robot and the checks in the browser (a local web app)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import typer

from tablebot import i18n
from tablebot.cli.app import app
from tablebot.cli.common import err_console, guarded
from tablebot.diagnostics import fail, severity_word
from tablebot.escape import terminal
from tablebot.i18n import N_, _

if TYPE_CHECKING:
    import socket

LOCAL = "127.0.0.1"


@app.command("studio")
@guarded
def studio_cmd(
    where: Path = typer.Argument(
        Path("."), metavar="FOLDER", help="A folder (its table.csv opens first) or a table file."
    ),
    port: int = typer.Option(8765, "--port", min=0, max=65535, help="Port to serve on (0: any free port)."),
    host: str | None = typer.Option(
        None,
        "--host",
        help="Serve on this address instead of 127.0.0.1, "
        "e.g. 0.0.0.0 for the whole network (anyone with the printed address and its "
        "token can read and change the folder's tables).",
    ),
    no_browser: bool = typer.Option(False, "--no-browser", help="Do not open a browser."),
    verbose: bool = typer.Option(False, "--verbose", "-v", help="Print every request (the token shown as [token])."),
    open_link: str | None = typer.Option(
        None,
        "--open",
        metavar="LINK",
        help="Open the table a share link "
        "carries (tablebot share): its files go into a new folder in FOLDER, "
        "named as the link names it, and its table opens.",
    ),
) -> None:
    """Edit a table in the browser, see its checks as you type, and watch the robot run it live.

    The address printed (and opened) carries a secret token made at each start: only a page opened from
    it can use the studio. The browser is given a file only you can read that leads to it, so that no
    command line (which every user of the computer can see) holds the token."""
    import threading
    from contextlib import ExitStack
    from urllib.parse import quote

    from tablebot.web import sharing
    from tablebot.web.access import WILDCARDS, Access
    from tablebot.web.app import create_app, server
    from tablebot.web.launch import open_in_browser, redirect_file

    root, table = _root_and_table(where)
    if open_link is not None:
        table = _unpack_link(root, open_link)
    address = host or LOCAL
    sock = _bind(address, port)
    access = Access.serving(address, sock.getsockname()[1])
    if not _loopback(address):
        _warn_network(root, address, access.port)
    shown = LOCAL if address in WILDCARDS else address
    url = access.url(shown, f"table={quote(table)}" if table else "")
    err_console.print(_("tablebot studio: serving {folder} at").format(folder=terminal(str(root))), soft_wrap=True)
    err_console.print(f"  {url}", soft_wrap=True, markup=False)  # whole, never wrapped: it is the key
    if address in WILDCARDS:
        import socket

        other = access.url(socket.gethostname(), f"table={quote(table)}" if table else "")
        err_console.print(
            "  " + _("{address}  (from other machines)").format(address=other), soft_wrap=True, markup=False
        )
    err_console.print(_("(Ctrl-C stops; each start makes a new token)"), soft_wrap=True)
    if table is None:
        _say_no_table(root)
    sharing.maker, sharing.opener = link_maker, link_opener  # the Share button's links, and links pasted in
    visited = threading.Event()
    uvicorn_server = server(
        create_app(root, access, table, visited=visited, lang=i18n.named()), access, "info" if verbose else "warning"
    )
    with ExitStack() as stack:  # the file goes when the studio stops (Ctrl-C, SIGTERM)
        if not no_browser:
            open_in_browser(stack.enter_context(redirect_file(url)), visited)
        uvicorn_server.run(sockets=[sock])


def _loopback(address: str) -> bool:
    """Whether only this machine reaches ``address`` (127.x.x.x, ::1, localhost)."""
    import ipaddress

    try:
        return ipaddress.ip_address(address.strip("[]")).is_loopback
    except ValueError:
        return address.lower() == "localhost"


def _warn_network(root: Path, address: str, port: int) -> None:
    err_console.print(
        f"[bold red]{severity_word('warning')}:[/bold red] "
        + _(
            "serving {folder} on {address}:{port}, not only to this machine: anyone who can reach it and has the "
            "address below (with its token) can read the folder's tables, robot and world files and traces, and change "
            "its tables. The connection is plain HTTP: anyone who can watch the network can see the token."
        ).format(folder=terminal(str(root)), address=terminal(address), port=port),
        soft_wrap=True,
    )


def link_maker(table: Path, text: str) -> tuple[str, str]:
    """The studio's Share button: ``tablebot share``'s link for the table at ``table`` with ``text`` (the draft on
    the page) as its contents, checked as every command reads it, and its QR code as an SVG data: address."""
    import segno

    from tablebot import share

    shared = share.collect(table).with_text(table.name, text)  # a robot of several: all its tables, this as edited
    shared.check("the table")
    link = share.encode(shared)
    try:
        qr = segno.make(link, error="l", boost_error=True, micro=False).svg_data_uri(scale=3, border=4)
    except segno.DataOverflowError:
        qr = ""  # the page shows the link alone
    return link, qr


def _unpack_link(root: Path, link: str) -> str:
    """``--open LINK``: :func:`link_opener`, and the terminal says where the files went."""
    table = link_opener(root, link, "--open")
    err_console.print(
        f"tablebot studio: the link's table is {terminal(table)} in {terminal(str(root))} (with "
        "its robot file and world), as it was shared",
        soft_wrap=True,
    )
    return table


def link_opener(root: Path, link: str, where: str = "the link") -> str:
    """Write the files a share link carries into a new folder of ``root`` (never over anything: NAME, NAME-2,
    ...), exactly as shared; the table's name relative to ``root``. A link that is no link, cut, damaged, from
    another version or carrying a broken table is refused in words, naming ``where``."""
    from tablebot import share

    shared = share.decode(link, where)
    shared.check(where)
    folder = next(
        root / name
        for name in (shared.name, *(f"{shared.name}-{n}" for n in range(2, 1000)))
        if not (root / name).exists() and not (root / name).is_symlink()
    )
    return shared.write(folder).relative_to(root).as_posix()


def _say_no_table(root: Path) -> None:
    """A folder without a table (a pupil in the wrong folder: the default is the current one): say so, and how
    to start one, as the page does."""
    from tablebot.templates import TEMPLATES
    from tablebot.web.workspace import Workspace

    if Workspace(root).listing()["tables"]:
        return  # another table there: the page opens it
    err_console.print(
        f"[yellow]{severity_word('note')}:[/yellow] "
        + _(
            "there is no table in {folder} (a .csv or .tsv whose first line names the state and next columns). Start "
            "one from a template, then open it:"
        ).format(folder=terminal(str(root))),
        soft_wrap=True,
    )
    for name in TEMPLATES:
        err_console.print(f"  tablebot new my-robot --from {name}", soft_wrap=True, markup=False)
    err_console.print("  tablebot studio my-robot", soft_wrap=True, markup=False)


def _root_and_table(where: Path) -> tuple[Path, str | None]:
    """The served folder and the table to open first (relative to it)."""
    if not where.exists():
        raise fail(where, N_("no such file or folder"), N_("give a folder that holds a table, or a table file"))
    if where.is_dir():
        first = next((name for name in ("table.csv", "table.tsv") if (where / name).is_file()), None)
        return where.resolve(), first
    return where.resolve().parent, where.name


def _bind(address: str, port: int) -> socket.socket:
    import errno
    import socket

    address = address.strip("[]")  # an IPv6 literal as in a URL
    family = socket.AF_INET6 if ":" in address else socket.AF_INET
    sock = socket.socket(family, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind((address, port))
    except OSError as exc:
        sock.close()
        hint = (
            N_("choose another --port (0 picks a free one)")
            if exc.errno == errno.EADDRINUSE
            else N_("give --host an address of this machine")
        )
        raise fail(
            "--port" if exc.errno == errno.EADDRINUSE else "--host",
            N_("cannot serve on {address}:{port}: {reason}", address=address, port=port, reason=exc.strerror),
            hint,
        ) from None
    sock.listen(64)
    return sock
