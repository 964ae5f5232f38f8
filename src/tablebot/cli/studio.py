"""The ``studio`` command: the table, the live robot and the checks in the browser (a local web app)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import typer

from tablebot.cli.app import app
from tablebot.cli.common import err_console, guarded
from tablebot.diagnostics import fail

if TYPE_CHECKING:
    import socket

LOCAL = "127.0.0.1"


@app.command("studio")
@guarded
def studio_cmd(
    where: Path = typer.Argument(Path("."), help="A folder (its table.csv opens first) or a table file."),
    port: int = typer.Option(8765, "--port", min=0, max=65535, help="Port to serve on (0: any free port)."),
    host: str | None = typer.Option(None, "--host", help="Serve on this address instead of 127.0.0.1, "
                                    "e.g. 0.0.0.0 for the whole network (anyone who reaches it can edit tables)."),
    no_browser: bool = typer.Option(False, "--no-browser", help="Do not open a browser."),
) -> None:
    """Edit a table in the browser, see its checks as you type, and watch the robot run it live."""
    import webbrowser

    import uvicorn

    from tablebot.web.app import MAX_MESSAGE_BYTES, create_app

    root, table = _root_and_table(where)
    address = host or LOCAL
    sock = _bind(address, port)
    actual = sock.getsockname()[1]
    if host and host not in (LOCAL, "localhost", "::1"):
        err_console.print(f"[bold red]warning:[/bold red] serving {root} on {host}:{actual}: anyone who can reach "
                          "this machine can read the folder's tables and traces and change its tables")
    shown = LOCAL if address in ("0.0.0.0", "::") else address
    url = f"http://{shown}:{actual}/" + (f"?table={table}" if table else "")
    err_console.print(f"tablebot studio: serving {root} at {url}  (Ctrl-C stops)")
    config = uvicorn.Config(create_app(root, table), log_level="warning", ws_max_size=MAX_MESSAGE_BYTES,
                            lifespan="off")
    server = uvicorn.Server(config)
    if not no_browser:
        webbrowser.open(url)
    server.run(sockets=[sock])


def _root_and_table(where: Path) -> tuple[Path, str | None]:
    """The served folder and the table to open first (relative to it)."""
    if not where.exists():
        raise fail(where, "no such file or folder", "give a folder that holds a table, or a table file")
    if where.is_dir():
        first = next((name for name in ("table.csv", "table.tsv") if (where / name).is_file()), None)
        return where.resolve(), first
    return where.resolve().parent, where.name


def _bind(address: str, port: int) -> socket.socket:
    import errno
    import socket

    family = socket.AF_INET6 if ":" in address else socket.AF_INET
    sock = socket.socket(family, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind((address, port))
    except OSError as exc:
        sock.close()
        hint = "choose another --port (0 picks a free one)" if exc.errno == errno.EADDRINUSE else \
            "give --host an address of this machine"
        raise fail("--port" if exc.errno == errno.EADDRINUSE else "--host",
                   f"cannot serve on {address}:{port}: {exc.strerror}", hint) from None
    sock.listen(64)
    return sock
