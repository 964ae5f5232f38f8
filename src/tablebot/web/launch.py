"""Opening the studio in the user's browser without its token on any command line.

A browser started with the address as an argument keeps it in ``/proc/PID/cmdline`` as long as it runs,
and every user of a shared computer can read that. As Jupyter does, the browser is given a small local
file instead, which leads on to the address: written 0600 in a folder of its own (0700) in the user's
runtime folder (``$XDG_RUNTIME_DIR``) or else the temporary folder, and removed when the studio stops.
Only the user can read it; the address the terminal prints still carries the token, for the user's eyes.
The page that address opens takes the token out of the address bar and keeps it in its tab, never in a
cookie (see :mod:`.access`).
"""

from __future__ import annotations

import html
import os
import shutil
import stat
import tempfile
import threading
import webbrowser
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from tablebot.web.errors import log

PATIENCE_S = 20.0  # a cold browser on a slow school computer takes a while
PAGE = """<!doctype html>
<html><head><meta charset="utf-8"><meta name="referrer" content="no-referrer">
<meta http-equiv="refresh" content="0;url={url}"><title>tablebot studio</title></head>
<body><p>Opening tablebot studio&hellip; if nothing happens, <a href="{url}">open it here</a>.</p></body></html>
"""


@contextmanager
def redirect_file(url: str) -> Iterator[Path]:
    """A file only this user can read that sends the browser on to ``url``; removed when the block ends."""
    folder = Path(tempfile.mkdtemp(prefix="tablebot-studio-", dir=_runtime_folder()))  # 0700
    try:
        path = folder / "open.html"
        _write_private(path, PAGE.format(url=html.escape(url, quote=True)))
        yield path
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def _runtime_folder() -> str | None:
    """$XDG_RUNTIME_DIR when it is the user's own private folder (as systemd makes it), else None: the
    temporary folder ($TMPDIR, /tmp), where the folder made in it is private all the same."""
    folder = os.environ.get("XDG_RUNTIME_DIR")
    if not folder or not hasattr(os, "getuid"):  # not a Unix desktop session
        return None
    try:
        info = os.stat(folder)
    except OSError:
        return None
    private = stat.S_ISDIR(info.st_mode) and info.st_uid == os.getuid() and not info.st_mode & 0o077
    return folder if private else None


def _write_private(path: Path, text: str) -> None:
    """Written under a temporary name in the same (private) folder, 0600, then renamed into place."""
    fd, temp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)  # 0600
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as stream:
            stream.write(text)
        os.replace(temp, path)
    except BaseException:
        Path(temp).unlink(missing_ok=True)
        raise


def open_in_browser(path: Path, visited: threading.Event, patience_s: float = PATIENCE_S) -> None:
    """Open the local file ``path`` in the user's browser, from a thread of its own (a browser named by
    ``$BROWSER`` is waited for until it exits, and the studio must serve meanwhile); if the page has not
    ``visited`` the studio within ``patience_s``, say what to do. A browser installed as a snap (Ubuntu's
    Firefox and Chromium) cannot read the runtime or temporary folder and shows "file not found"."""

    def run() -> None:
        if not webbrowser.open(path.as_uri()):
            log.warning("no browser could be opened: open the address above in one")
        elif not visited.wait(patience_s):
            log.warning(
                "the browser has not come to the studio after %g s: if it cannot find %s (a browser "
                "installed as a snap cannot read that folder), open the address above",
                patience_s,
                path,
            )

    threading.Thread(target=run, name="tablebot-browser", daemon=True).start()
