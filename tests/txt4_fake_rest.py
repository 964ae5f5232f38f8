"""A fake TXT 4.0 REST API for the tests: a real HTTP server (in a thread) that answers as harbaum/SofTXT's
``txt-4.0.py`` does -- the path parsed as ``/api/v1/...`` with any query ignored, ``ping`` and ``stop``
answered, the files of a multipart POST to ``workspaces/NAME/files`` saved under the part's filename
(a leading ``/`` stripped), ``application/NAME/start`` started, ``GET workspaces/NAME`` found only once its
``.project.json`` exists -- plus a check of the ``X-API-KEY`` header, which SofTXT does not make and a
real controller does (the status a real one answers a wrong key with is unconfirmed: 401 here)."""

from __future__ import annotations

import email.message
import email.parser
import json
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path


class FakeTxt4:
    def __init__(self, root: Path, key: str = "SECRET") -> None:
        self.root, self.key = root, key
        self.calls: list[tuple[str, str]] = []
        self.keys: list[str | None] = []
        self.started: list[str] = []
        self.filenames: list[str] = []
        fake = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, *args: object) -> None:  # quiet
                pass

            def do_GET(self) -> None:
                fake.handle(self, "GET")

            def do_POST(self) -> None:
                fake.handle(self, "POST")

            def do_DELETE(self) -> None:
                fake.handle(self, "DELETE")

        self.server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.port = self.server.server_address[1]
        self.thread = threading.Thread(target=self.server.serve_forever, daemon=True)
        self.thread.start()

    def __enter__(self) -> FakeTxt4:
        return self

    def __exit__(self, *exc: object) -> None:
        self.server.shutdown()
        self.server.server_close()

    def handle(self, request: BaseHTTPRequestHandler, method: str) -> None:
        self.calls.append((method, request.path))
        self.keys.append(request.headers.get("X-API-KEY"))
        body = request.rfile.read(int(request.headers.get("Content-Length") or 0))
        if request.headers.get("X-API-KEY") != self.key:
            return self.reply(request, 401)
        parts = request.path.split("?")[0].split("/")
        if len(parts) < 4 or parts[:3] != ["", "api", "v1"]:
            return self.reply(request, 404)
        route = parts[3:]
        if (method, route) in (("GET", ["ping"]), ("DELETE", ["stop"])):
            return self.reply(request, 200)
        if route[:1] == ["workspaces"] and len(route) >= 2:
            folder = self.root / route[1]
            if method == "POST" and route[2:] == ["files"]:
                return self.save(request, folder, body)
            if method == "GET" and route[2:] == [] and (folder / ".project.json").is_file():
                return self.reply(request, 200)
            if method == "GET" and route[2:] == ["files"] and folder.is_dir():
                return self.reply(request, 200, [{"name": p.name, "path": str(p)} for p in folder.iterdir()])
        if method == "POST" and len(route) == 3 and route[0] == "application" and route[2] == "start":
            self.started.append(route[1])
            return self.reply(request, 200)
        return self.reply(request, 404)

    def save(self, request: BaseHTTPRequestHandler, folder: Path, body: bytes) -> None:
        """Multipart form data, one part per file, its path in the part's filename (as SofTXT reads it)."""
        head = f"Content-Type: {request.headers['Content-Type']}\r\n\r\n".encode()
        message = email.parser.BytesParser().parsebytes(head + body)
        parts = message.get_payload()
        assert isinstance(parts, list), "a multipart body"
        for part in parts:
            assert isinstance(part, email.message.Message)
            relative = part.get_param("filename", header="content-disposition")
            assert isinstance(relative, str), f"every part names its file: {relative!r}"
            self.filenames.append(relative)
            relative = relative[1:] if relative.startswith("/") else relative
            target = (folder / relative).resolve()
            if folder.resolve() not in target.parents:  # SofTXT would write there; a test never should
                return self.reply(request, 400)
            target.parent.mkdir(parents=True, exist_ok=True)
            payload = part.get_payload(decode=True)
            assert isinstance(payload, bytes)
            target.write_bytes(payload)
        return self.reply(request, 200)

    @staticmethod
    def reply(request: BaseHTTPRequestHandler, status: int, data: object = ()) -> None:
        body = json.dumps(list(data) if isinstance(data, tuple) else data).encode()
        request.send_response(status)
        request.send_header("Content-Type", "application/json")
        request.send_header("Content-Length", str(len(body)))
        request.end_headers()
        request.wfile.write(body)
