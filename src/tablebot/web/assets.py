"""The studio's own files (its page's scripts and style sheet), read from the package once and served from memory.

Starlette's ``StaticFiles`` looked each request's file up and read it on a worker thread: ~4 ms of the studio's
one event-loop thread per file here, for 28 modules and a style sheet at every page opened -- several times that
on a classroom's slowest computer. Here every file under the folder is read when the studio starts, with its type
and an ETag (a digest of its bytes). A request names a file by its exact path under the folder: nothing outside
it, no symbolic link and no file added later is ever served. A file changed on disk since (someone working on the
studio's scripts) is read again at its next request, and one removed is no longer served. The browser revalidates
each file at each use (``Cache-Control: no-cache``) and gets an empty 304 while it is unchanged.
"""

from __future__ import annotations

import hashlib
import mimetypes
import os
import stat
from dataclasses import dataclass
from pathlib import Path

from starlette.requests import Request
from starlette.responses import PlainTextResponse, Response

__all__ = ["Asset", "Assets"]

#: Types the browser reads as text: sent with their encoding.
TEXT_TYPES = ("text/", "application/javascript", "application/json", "image/svg+xml")


@dataclass(frozen=True)
class Asset:
    """One file as it is served: its bytes, type, ETag and the modification time it was read at."""

    body: bytes
    media_type: str
    etag: str
    mtime_ns: int


class Assets:
    """The files under ``root``, served by :meth:`endpoint` (a route's ``{path:path}`` names one)."""

    def __init__(self, root: Path) -> None:
        self.root = root.resolve()
        self.files: dict[str, Asset] = {}
        for folder, _dirs, names in os.walk(self.root):  # (os.walk follows no link to a folder)
            for name in names:
                path = Path(folder, name)
                asset = _read(path)
                if asset is not None:
                    self.files[path.relative_to(self.root).as_posix()] = asset

    def get(self, name: str) -> Asset | None:
        """The file ``name`` (a path under the folder, as read at the start), read again if it changed on disk;
        None if it is not one of them or is gone."""
        asset = self.files.get(name)
        if asset is None:
            return None
        path = self.root / name
        try:
            changed = os.lstat(path).st_mtime_ns != asset.mtime_ns
        except OSError:
            changed = True
        if changed:
            fresh = _read(path)
            if fresh is None:
                del self.files[name]
                return None
            self.files[name] = asset = fresh
        return asset

    async def endpoint(self, request: Request) -> Response:
        asset = self.get(request.path_params["path"])
        if asset is None:
            return PlainTextResponse("Not Found", status_code=404)
        headers = {"ETag": asset.etag, "Cache-Control": "no-cache"}
        if asset.etag in request.headers.get("if-none-match", ""):
            return Response(status_code=304, headers=headers)
        return Response(asset.body, media_type=asset.media_type, headers=headers)  # (no body to a HEAD: uvicorn)


def _read(path: Path) -> Asset | None:
    """The file at ``path`` as served, or None if it is not a regular file (a link, a folder, gone)."""
    try:
        before = os.lstat(path)  # the entry itself: a link is not a regular file here
        if not stat.S_ISREG(before.st_mode):
            return None
        body = path.read_bytes()
    except OSError:
        return None
    media_type = mimetypes.guess_type(path.name)[0] or "application/octet-stream"
    if media_type.startswith(TEXT_TYPES):
        media_type += "; charset=utf-8"
    etag = '"' + hashlib.sha1(body).hexdigest()[:20] + '"'
    return Asset(body, media_type, etag, before.st_mtime_ns)
