"""The studio's own files served from memory (tablebot.web.assets), over a real socket: each file under the folder
with its type and ETag, 304 while unchanged, read again when changed on disk, and nothing else -- no path out of the
folder, no symbolic link, no file added or removed since the start."""

from __future__ import annotations

import os
import socket
import threading
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import pytest
import uvicorn
from starlette.applications import Starlette
from starlette.routing import Route

from tablebot.web.app import STATIC
from tablebot.web.assets import Assets

pytestmark = [pytest.mark.kernel_free]


@pytest.fixture
def served(tmp_path: Path) -> Iterator[tuple[str, Path]]:
    """The files of a folder served as the studio serves its own, at an address on loopback."""
    root = tmp_path / "static"
    (root / "js").mkdir(parents=True)
    (root / "js" / "main.js").write_text('import { a } from "./a.js";\n', encoding="utf-8")
    (root / "style.css").write_text("body { margin: 0 }\n", encoding="utf-8")
    (tmp_path / "secret.txt").write_text("not for the browser\n", encoding="utf-8")
    (root / "link.txt").symlink_to(tmp_path / "secret.txt")
    (root / "linked").symlink_to(tmp_path, target_is_directory=True)
    app = Starlette(routes=[Route("/static/{path:path}", Assets(root).endpoint, methods=["GET", "HEAD"])])
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    sock.bind(("127.0.0.1", 0))
    server = uvicorn.Server(uvicorn.Config(app, log_level="warning"))
    thread = threading.Thread(target=server.run, kwargs={"sockets": [sock]}, daemon=True)
    thread.start()
    while not server.started:
        time.sleep(0.01)
    yield f"http://127.0.0.1:{sock.getsockname()[1]}/static/", root
    server.should_exit = True
    thread.join(10)


def fetch(url: str, method: str = "GET", **headers: str) -> tuple[int, dict[str, str], bytes]:
    request = urllib.request.Request(url, method=method, headers=headers)
    try:
        with urllib.request.urlopen(request, timeout=10) as reply:
            return reply.status, dict(reply.headers), reply.read()
    except urllib.error.HTTPError as err:
        return err.code, dict(err.headers), err.read()


def test_each_file_comes_with_its_type_and_a_304_while_it_is_unchanged(served: tuple[str, Path]) -> None:
    base, _ = served
    status, headers, body = fetch(base + "js/main.js")
    assert status == 200 and body == b'import { a } from "./a.js";\n'
    assert "javascript" in headers["content-type"] and "charset=utf-8" in headers["content-type"]
    assert headers["cache-control"] == "no-cache" and headers["etag"].startswith('"')
    assert fetch(base + "js/main.js", **{"If-None-Match": headers["etag"]})[::2] == (304, b"")
    status, headers, body = fetch(base + "style.css", "HEAD")
    assert status == 200 and body == b"" and headers["content-length"] == str(len("body { margin: 0 }\n"))
    assert headers["content-type"].startswith("text/css")


@pytest.mark.parametrize(
    "path", ["../secret.txt", "%2e%2e/secret.txt", "..%2fsecret.txt", "link.txt", "linked/secret.txt", "js", ""]
)
def test_nothing_outside_the_files_of_the_folder_is_served(served: tuple[str, Path], path: str) -> None:
    base, _ = served
    status, _, body = fetch(base + path)
    assert status == 404 and b"not for the browser" not in body


def test_a_file_changed_on_disk_is_served_anew_one_removed_or_added_is_not(served: tuple[str, Path]) -> None:
    base, root = served
    etag = fetch(base + "style.css")[1]["etag"]
    (root / "style.css").write_text("body { margin: 1em }\n", encoding="utf-8")
    os.utime(root / "style.css", ns=(time.time_ns(), time.time_ns() + 1_000_000))  # however coarse the clock
    status, headers, body = fetch(base + "style.css", **{"If-None-Match": etag})
    assert (status, body) == (200, b"body { margin: 1em }\n") and headers["etag"] != etag
    (root / "js" / "main.js").unlink()
    assert fetch(base + "js/main.js")[0] == 404
    (root / "new.js").write_text("export const b = 1;\n", encoding="utf-8")
    assert fetch(base + "new.js")[0] == 404  # only what was there when the studio started


def test_the_studio_s_own_files_are_all_of_the_package_s_static_folder() -> None:
    files = Assets(STATIC).files
    on_disk = {p.relative_to(STATIC).as_posix() for p in STATIC.rglob("*") if p.is_file()}
    assert set(files) == on_disk and "js/studio/main.js" in files and "index.html" in files
    assert all(files[name].body == (STATIC / name).read_bytes() for name in files)
