"""``tablebot upload``: put an exported TXT 4.0 program onto the controller and start it, through the REST
API ROBO Pro Coding uses.

Where each part comes from (none was tried on a real TXT 4.0; see docs/controllers.md):

- ``GET /api/v1/ping``, ``DELETE /api/v1/stop``, ``POST /api/v1/workspaces/NAME/files`` (multipart form
  data, a part per file, the file's path in the workspace as the part's filename) and ``POST
  /api/v1/application/NAME/start``: harbaum/SofTXT ``txt-4.0.py``, a software TXT 4.0 that serves what
  ROBO Pro Coding asks of the controller; the start route also in Computer-Vision-Group-Siegen/
  cvtxtclient ``js-ui/cat_ctrl.js``. SofTXT makes the workspace folder when the files arrive; no
  source shows a separate "create workspace" call, so none is made.
- Paths start with ``/`` (``/lib/tablebot_program.py``): SofTXT strips a leading ``/``, written for
  what ROBO Pro Coding sends (*inferred*).
- The key in the header ``X-API-KEY``: cvtxtclient (``cvtxtclient/api/controller.py`` ``get_headers``,
  ``js-ui/cat_ctrl.js``), a client of the real controller's API. SofTXT checks no key.
- Port 80: cvtxtclient's page talks to ``http://txt40.local/api/v1/`` (no port). SofTXT listens on 8000
  (give ``txt4://HOST:8000``).
"""

from __future__ import annotations

import json
import os
import re
import sys
from collections.abc import Callable
from pathlib import Path

import httpx

from tablebot.diagnostics import fail
from tablebot.i18n import N_

DEFAULT_PORT = 80
KEY_ENV = "TABLEBOT_TXT4_KEY"
URL_HINT = N_("write --to txt4://192.168.7.2 (USB), txt4://192.168.8.2 (Wi-Fi) or txt4://HOST:PORT")
KEY_HINT = N_(
    "give the key the TXT 4.0 shows (the one ROBO Pro Coding asks for) in ${env}, with --key-file FILE, "
    "at the prompt (run it in a terminal), or with --key KEY",
    env=KEY_ENV,
)
NAME_RE = re.compile(r"^[A-Za-z0-9_-]{1,64}$")


def base_url(target: str) -> str:
    """``txt4://HOST[:PORT]`` as ``http://HOST:PORT``; anything else is an error naming ``--to``."""
    match = re.fullmatch(r"txt4://([A-Za-z0-9.-]+)(?::(\d{1,5}))?/?", target)
    if not match or (match[2] and not 0 < int(match[2]) < 65536):
        raise fail("--to", N_("{target!r} is not txt4://HOST or txt4://HOST:PORT", target=target), URL_HINT)
    return f"http://{match[1]}:{match[2] or DEFAULT_PORT}"


def api_key(key: str | None, key_file: Path | None, prompt: Callable[[], str] | None) -> str:
    """The key from ``--key``, ``--key-file``, ``$TABLEBOT_TXT4_KEY`` or ``prompt`` (None: not a terminal),
    first found first; ``--key`` puts it in the process list and the shell's history, the others do not."""
    if key is not None and key_file is not None:
        raise fail("--key", N_("give the key once: --key or --key-file, not both"), KEY_HINT)
    if key_file is not None:
        try:
            key = key_file.read_text(encoding="utf-8").strip()
        except (OSError, UnicodeDecodeError) as exc:
            raise fail(
                key_file,
                N_("cannot read the key file: {reason}", reason=getattr(exc, "strerror", None) or exc),
                N_("the file holds the key the TXT 4.0 shows, on one line"),
            ) from None
        if not key:
            raise fail(key_file, N_("the key file is empty"), N_("write the key the TXT 4.0 shows into it"))
    key = key if key is not None else os.environ.get(KEY_ENV) or None
    if key is None and prompt is not None:
        key = prompt().strip()
    if not key:
        raise fail("--key", N_("no API key"), KEY_HINT)
    if not key.isprintable() or len(key) > 256:
        raise fail("--key", N_("the API key holds control characters or is too long"), KEY_HINT)
    return key


def workspace_files(folder: Path) -> tuple[str, dict[str, bytes]]:
    """The workspace's name (from ``.project.json``) and its files by path in the workspace (``/...``)."""
    project = folder / ".project.json"
    try:
        name = json.loads(project.read_text(encoding="utf-8")).get("name")
    except (OSError, ValueError, AttributeError):
        name = None
    if not isinstance(name, str) or not NAME_RE.match(name):
        raise fail(
            folder,
            N_("this folder is not a program written by `tablebot export --to txt4`"),
            N_("export one first: tablebot export TABLE OUTDIR --to txt4"),
        )
    files = {
        "/" + p.relative_to(folder).as_posix(): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and "__pycache__" not in p.parts
    }
    return name, files


def upload(
    folder: Path, target: str, key: str, start: bool = True, timeout_s: float = 10.0, say: Callable[[str], None] = print
) -> str:
    """Stop whatever runs, send the workspace's files, start it; returns the workspace name."""
    url = base_url(target)
    name, files = workspace_files(folder)
    with httpx.Client(base_url=url, headers={"X-API-KEY": key}, timeout=timeout_s) as client:
        _call(client, "GET", "/api/v1/ping", target)
        _call(client, "DELETE", "/api/v1/stop", target)
        form = [("files", (path, data, "text/plain")) for path, data in files.items()]
        _call(client, "POST", f"/api/v1/workspaces/{name}/files", target, files=form)
        say(N_("uploaded {n} files to workspace {name} on {target}", n=len(files), name=name, target=target))
        if start:
            _call(client, "POST", f"/api/v1/application/{name}/start", target)
            say(
                N_(
                    "started {name}; stop it on the controller, or: curl -X DELETE {url}/api/v1/stop",
                    name=name,
                    url=url,
                )
            )
    return name


def _call(client: httpx.Client, method: str, path: str, target: str, **kwargs: object) -> httpx.Response:
    try:
        response = client.request(method, path, **kwargs)  # type: ignore[arg-type]
    except httpx.TimeoutException:
        raise fail(
            "--to",
            N_("{target} did not answer {method} {path} in time", target=target, method=method, path=path),
            N_("is the TXT 4.0 on, and this computer on its USB or Wi-Fi network?"),
        ) from None
    except httpx.HTTPError as exc:
        raise fail(
            "--to",
            N_("cannot reach {target}: {reason}", target=target, reason=str(exc)),
            N_("is the TXT 4.0 on, and this computer on its USB or Wi-Fi network?"),
        ) from None
    if response.status_code in (401, 403):
        raise fail(
            "--key",
            N_(
                "{target} refused the API key ({status} on {method} {path})",
                target=target,
                status=response.status_code,
                method=method,
                path=path,
            ),
            N_("the TXT 4.0 shows a new key now and then: read it again from its display"),
        )
    if response.status_code >= 400:
        raise fail(
            "--to",
            N_(
                "{target} answered {status} to {method} {path}",
                target=target,
                status=response.status_code,
                method=method,
                path=path,
            ),
            N_("check that it is a TXT 4.0 with the ROBO Pro Coding interface switched on"),
        )
    return response


def terminal_prompt() -> Callable[[], str] | None:
    """A hidden prompt for the key when stdin is a terminal, else None (never wait on a pipe)."""
    if not sys.stdin.isatty():
        return None
    import typer

    return lambda: typer.prompt("API key of the TXT 4.0 (shown on its display)", hide_input=True)
