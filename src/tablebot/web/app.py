"""The studio's web server: the page and its scripts from the package, one WebSocket per tab, trace
uploads; it serves one folder and nothing outside it.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
from pathlib import Path
from typing import Any

from starlette.applications import Starlette
from starlette.requests import Request
from starlette.responses import FileResponse, JSONResponse, Response
from starlette.routing import Mount, Route, WebSocketRoute
from starlette.staticfiles import StaticFiles
from starlette.websockets import WebSocket, WebSocketDisconnect, WebSocketState

from tablebot.diagnostics import TableBotError
from tablebot.web.session import Hub, Session
from tablebot.web.tracefile import MAX_TRACE_BYTES, read_trace_bytes, trace_columns
from tablebot.web.workspace import Workspace

STATIC = Path(__file__).parent / "static"
FRAME_S = 0.04  # 25 frames a second: smooth to the eye, whatever the simulation's speed
MAX_MESSAGE_BYTES = 2 * 1024 * 1024  # an edit is a cell; a whole table is at most 1 MB
#: Scripts and styles only from this server; nothing from the internet.
CSP = ("default-src 'self'; script-src 'self'; style-src 'self' 'unsafe-inline'; img-src 'self' data:; "
       "connect-src 'self'; object-src 'none'; base-uri 'none'; frame-ancestors 'none'")


class Gone(Exception):
    """The tab closed its WebSocket: stop talking to it."""


def create_app(root: Path, table: str | None = None) -> Starlette:
    """The studio for folder ``root``; ``table`` (relative to it) opens first."""
    workspace = Workspace(root)
    hub = Hub()

    async def index(request: Request) -> Response:
        response = FileResponse(STATIC / "index.html", headers={"Content-Security-Policy": CSP,
                                                                "Cache-Control": "no-store"})
        return response

    async def config(request: Request) -> Response:
        return JSONResponse({"table": table, "folder": workspace.root.name, **workspace.listing()})

    async def upload_trace(request: Request) -> Response:
        """A trace file from the user's computer (the body), size-limited while it arrives."""
        name = request.query_params.get("name", "uploaded trace")[:200]
        body = bytearray()
        async for chunk in request.stream():
            body += chunk
            if len(body) > MAX_TRACE_BYTES:
                return JSONResponse({"type": "error", "message": f"the trace is larger than {MAX_TRACE_BYTES:,} "
                                     "bytes", "hint": "cut the run shorter"}, status_code=413)
        try:
            lines = await asyncio.to_thread(read_trace_bytes, bytes(body), name)
        except TableBotError as exc:
            return JSONResponse({"type": "error", "message": str(exc)}, status_code=400)
        return JSONResponse({"type": "trace", "name": name, "columns": trace_columns(lines)})

    async def socket(websocket: WebSocket) -> None:
        await websocket.accept()
        lock = asyncio.Lock()

        async def send(message: dict[str, Any]) -> None:
            async with lock:
                if websocket.application_state != WebSocketState.CONNECTED:
                    raise Gone
                try:
                    await websocket.send_text(json.dumps(message, separators=(",", ":")))
                except (WebSocketDisconnect, RuntimeError, OSError) as exc:  # the tab went away mid-send
                    raise Gone from exc

        session = Session(workspace, hub, send)
        hub.sessions.add(session)
        ticker = asyncio.create_task(_frames(session))
        try:
            while True:
                text = await websocket.receive_text()
                await _answer(session, text)
        except (WebSocketDisconnect, Gone):
            pass
        finally:
            ticker.cancel()
            hub.sessions.discard(session)
            await asyncio.to_thread(session.close)

    routes = [Route("/", index), Route("/api/config", config), Route("/api/trace", upload_trace, methods=["POST"]),
              WebSocketRoute("/ws", socket), Mount("/static", StaticFiles(directory=STATIC), name="static")]
    return Starlette(routes=routes)


async def _answer(session: Session, text: str) -> None:
    """One message from the page; nothing it sends can end the connection or the server."""
    if len(text) > MAX_MESSAGE_BYTES:
        await session.error(f"message too large ({len(text):,} characters)")
        return
    try:
        message = json.loads(text)
    except json.JSONDecodeError as exc:
        await session.error(f"not JSON: {exc.msg}")
        return
    try:
        await session.handle(message)
    except Gone:
        raise
    except Exception as exc:  # a bug: say so on the page and keep serving
        await session.error(f"internal error: {type(exc).__name__}: {exc}")


async def _frames(session: Session) -> None:
    """The live robot's frames, until the tab goes; a failure is reported once and ends only the frames."""
    while True:
        await asyncio.sleep(FRAME_S)
        try:
            await session.frame()
        except Gone:
            return
        except Exception as exc:
            with contextlib.suppress(Exception):  # the socket itself may be what failed
                await session.error(f"the live view stopped: {type(exc).__name__}: {exc}")
            return


class Background:
    """The studio served from a thread (tests, benchmarks): ``url`` while running, :meth:`stop` to end."""

    def __init__(self, root: Path, table: str | None = None, host: str = "127.0.0.1", port: int = 0):
        import socket
        import threading

        import uvicorn

        self.sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.sock.bind((host, port))
        self.sock.listen(64)
        self.url = f"http://{host}:{self.sock.getsockname()[1]}/"
        config = uvicorn.Config(create_app(root, table), log_level="warning", ws_max_size=MAX_MESSAGE_BYTES,
                                lifespan="off")
        self.server = uvicorn.Server(config)
        self.thread = threading.Thread(target=self.server.run, kwargs={"sockets": [self.sock]}, daemon=True)
        self.thread.start()
        while not self.server.started:
            if not self.thread.is_alive():
                raise RuntimeError("the studio server did not start")
            threading.Event().wait(0.02)

    def stop(self) -> None:
        self.server.should_exit = True
        self.thread.join(10)
        self.sock.close()
