"""A fake TXT 4.0 REST API for the tests: a real HTTP server (in a thread) serving the routes ROBO Pro Coding
uses, as harbaum/SofTXT's txt-4.0.py serves them, plus the X-API-KEY check a real controller makes. It keeps
the files it is sent in a folder and records every request."""

from __future__ import annotations

import email.parser
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from urllib.parse import parse_qs, urlsplit


class FakeTxt4:
    def __init__(self, root: Path, key: str = "SECRET"):
        self.root, self.key = root, key
        self.calls: list[tuple[str, str]] = []
        self.started: list[str] = []
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
        url = urlsplit(request.path)
        self.calls.append((method, request.path))
        body = request.rfile.read(int(request.headers.get("Content-Length") or 0))
        if request.headers.get("X-API-KEY") != self.key:
            return self.reply(request, 401)
        parts = url.path.split("/")[1:]
        if parts[:2] != ["api", "v1"]:
            return self.reply(request, 404)
        route = parts[2:]
        if (method, route) in (("GET", ["ping"]), ("DELETE", ["stop"])):
            return self.reply(request, 200)
        if method == "POST" and route == ["workspaces"]:
            (name,) = parse_qs(url.query)["workspace_name"]
            (self.root / name).mkdir(parents=True, exist_ok=True)
            return self.reply(request, 200)
        if method == "POST" and len(route) == 3 and route[0] == "workspaces" and route[2] == "files":
            return self.save(request, route[1], body)
        if method == "POST" and len(route) == 3 and route[0] == "application" and route[2] == "start":
            self.started.append(route[1])
            return self.reply(request, 200)
        return self.reply(request, 404)

    def save(self, request: BaseHTTPRequestHandler, name: str, body: bytes) -> None:
        """Multipart form data, one part per file, its path in the part's filename (as SofTXT reads it)."""
        folder = self.root / name
        if not folder.is_dir():
            return self.reply(request, 404)
        head = f"Content-Type: {request.headers['Content-Type']}\r\n\r\n".encode()
        message = email.parser.BytesParser().parsebytes(head + body)
        for part in message.get_payload():
            relative = part.get_param("filename", header="content-disposition").lstrip("/")
            target = (folder / relative).resolve()
            if folder.resolve() not in target.parents:
                return self.reply(request, 400)
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(part.get_payload(decode=True))
        return self.reply(request, 200)

    @staticmethod
    def reply(request: BaseHTTPRequestHandler, status: int) -> None:
        request.send_response(status)
        request.send_header("Content-Type", "application/json")
        request.send_header("Content-Length", "2")
        request.end_headers()
        request.wfile.write(b"[]")
