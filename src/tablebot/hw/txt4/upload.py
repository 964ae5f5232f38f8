"""``tablebot upload``: put an exported TXT 4.0 program onto the controller and start it, through the REST
API ROBO Pro Coding uses (header ``X-API-KEY``; routes as harbaum/SofTXT's ``txt-4.0.py`` serves them:
ping, stop, create a workspace, send its files as multipart form data, start the application).

Not tried on a real TXT 4.0 (none was at hand): the routes, the header and the form layout come from
SofTXT, a software stand-in for the controller; the HTTP port of a real controller is assumed to be 80
(SofTXT has to be told ``:8000``). The tests use a fake server of these routes over real HTTP.
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable
from pathlib import Path

import httpx

from tablebot.diagnostics import fail

DEFAULT_PORT = 80
URL_HINT = "write --to txt4://192.168.7.2 (USB), txt4://192.168.8.2 (Wi-Fi) or txt4://HOST:PORT"
NAME_RE = re.compile(r"^[A-Za-z0-9_-]{1,64}$")


def base_url(target: str) -> str:
    """``txt4://HOST[:PORT]`` as ``http://HOST:PORT``; anything else is an error naming ``--to``."""
    match = re.fullmatch(r"txt4://([A-Za-z0-9.-]+)(?::(\d{1,5}))?/?", target)
    if not match or (match[2] and not 0 < int(match[2]) < 65536):
        raise fail("--to", f"{target!r} is not txt4://HOST or txt4://HOST:PORT", URL_HINT)
    return f"http://{match[1]}:{match[2] or DEFAULT_PORT}"


def workspace_files(folder: Path) -> tuple[str, dict[str, bytes]]:
    """The workspace's name (from ``.project.json``) and its files by relative path."""
    project = folder / ".project.json"
    try:
        name = json.loads(project.read_text(encoding="utf-8")).get("name")
    except (OSError, ValueError, AttributeError):
        name = None
    if not isinstance(name, str) or not NAME_RE.match(name):
        raise fail(folder, "this folder is not a program written by `tablebot export --to txt4`",
                   "export one first: tablebot export TABLE OUTDIR --to txt4")
    files = {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*"))
             if p.is_file() and "__pycache__" not in p.parts}
    return name, files


def upload(folder: Path, target: str, key: str, start: bool = True, timeout_s: float = 10.0,
           say: Callable[[str], None] = print) -> str:
    """Stop whatever runs, create the workspace, send its files, start it; returns the workspace name."""
    url = base_url(target)
    name, files = workspace_files(folder)
    with httpx.Client(base_url=url, headers={"X-API-KEY": key}, timeout=timeout_s) as client:
        _call(client, "GET", "/api/v1/ping", target)
        _call(client, "DELETE", "/api/v1/stop", target)
        _call(client, "POST", "/api/v1/workspaces", target, params={"workspace_name": name})
        form = [("files", (path, data, "text/plain")) for path, data in files.items()]
        _call(client, "POST", f"/api/v1/workspaces/{name}/files", target, files=form)
        say(f"uploaded {len(files)} files to workspace {name} on {target}")
        if start:
            _call(client, "POST", f"/api/v1/application/{name}/start", target)
            say(f"started {name}; stop it on the controller, or: DELETE {url}/api/v1/stop")
    return name


def _call(client: httpx.Client, method: str, path: str, target: str, **kwargs: object) -> httpx.Response:
    try:
        response = client.request(method, path, **kwargs)  # type: ignore[arg-type]
    except httpx.TimeoutException:
        raise fail("--to", f"{target} did not answer {method} {path} in time",
                   "is the TXT 4.0 on, and this computer on its USB or Wi-Fi network?") from None
    except httpx.HTTPError as exc:
        raise fail("--to", f"cannot reach {target}: {exc}",
                   "is the TXT 4.0 on, and this computer on its USB or Wi-Fi network?") from None
    if response.status_code in (401, 403):
        raise fail("--key", f"{target} refused the API key ({response.status_code} on {method} {path})",
                   "use the key the TXT 4.0 shows in its settings (the one ROBO Pro Coding asks for)")
    if response.status_code >= 400:
        raise fail("--to", f"{target} answered {response.status_code} to {method} {path}",
                   "check that it is a TXT 4.0 with the ROBO Pro Coding interface switched on")
    return response
