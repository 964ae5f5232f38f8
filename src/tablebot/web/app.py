"""The studio's web server: the page and its scripts from the package, one WebSocket per tab, trace
uploads; it serves one folder and nothing outside it, and only to its own page (see :mod:`.access`).
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import uvicorn
from starlette.applications import Starlette
from starlette.requests import ClientDisconnect, Request
from starlette.responses import HTMLResponse, JSONResponse, Response
from starlette.routing import Route, WebSocketRoute
from starlette.websockets import WebSocket, WebSocketDisconnect, WebSocketState

from tablebot.diagnostics import TableBotError
from tablebot.escape import terminal
from tablebot.i18n import N_
from tablebot.templates import TEMPLATES
from tablebot.web.access import TOKEN_HEADER, Access, Gate, hide_token_in_logs, subprotocol
from tablebot.web.assets import Assets
from tablebot.web.bundle import module_order
from tablebot.web.errors import INTERNAL, log
from tablebot.web.live import give_back_memory
from tablebot.web.protocol import ErrorMsg, TraceMsg
from tablebot.web.session import Hub, Session
from tablebot.web.tracefile import MAX_PLAYER_TRACE_BYTES, read_trace_bytes, trace_columns
from tablebot.web.words import language_of
from tablebot.web.workspace import Workspace

STATIC = Path(__file__).parent / "static"
FRAME_S = 0.04  # 25 frames a second: smooth to the eye, whatever the simulation's speed
MAX_MESSAGE_BYTES = 2 * 1024 * 1024  # an edit is a cell; a whole table is at most 1 MB
#: Tabs one studio serves at once, each with its own live robot (a thread): 60 made a new request wait 20 s.
#: More than a pupil opens; one more is told why (benchmarks/studio_tabs.py measures a full studio).
MAX_TABS = 8
TIDY_AFTER_S = 0.25  # tabs closing together (a window of them) go within this; their memory goes back at once
#: Scripts and styles only from this server; nothing from the internet.
CSP = (
    "default-src 'self'; script-src 'self'; style-src 'self' 'unsafe-inline'; img-src 'self' data:; "
    "connect-src 'self'; object-src 'none'; base-uri 'none'; frame-ancestors 'none'"
)


#: The page's first module, under STATIC.
ENTRY = "js/studio/main.js"


def index_page() -> str:
    """The studio's page, with a ``modulepreload`` link for every module its script imports, however deep:
    the browser asks for all of them at once instead of finding each level of imports only when the level
    above has arrived (five round trips in a row: ~0.2 s of each page opened on this machine, more over a
    classroom's Wi-Fi)."""
    html = (STATIC / "index.html").read_text(encoding="utf-8")
    script = f'<script type="module" src="/static/{ENTRY}"></script>'
    if script not in html:
        raise RuntimeError(f"index.html no longer loads /static/{ENTRY}")
    links = "".join(f'<link rel="modulepreload" href="/static/{name}">\n' for name in module_order(STATIC, ENTRY))
    return html.replace(script, links + script)


class Gone(Exception):
    """The tab closed its WebSocket: stop talking to it."""


def create_app(
    root: Path,
    access: Access,
    table: str | None = None,
    max_tabs: int = MAX_TABS,
    visited: threading.Event | None = None,
    lang: str | None = None,
) -> Gate:
    """The studio for folder ``root``, behind ``access``'s gate; ``table`` (relative to it) opens first;
    at most ``max_tabs`` tabs at once; ``visited`` is set when a page comes with the token in its address;
    ``lang`` is the language asked for (``tablebot studio --lang``), which the page speaks unless its switch says
    otherwise (None: the browser's language)."""
    workspace = Workspace(root)
    hub = Hub()
    tabs = Tabs(max_tabs)

    page = index_page()
    assets = Assets(STATIC)  # the page's scripts and style, read once

    async def index(request: Request) -> Response:
        response = HTMLResponse(page, headers={"Content-Security-Policy": CSP, "Cache-Control": "no-store"})
        if visited is not None and access.has_token(request.query_params.getlist("token")):
            visited.set()  # the browser came with the token (the page keeps it; the server sets no cookie)
        return response

    async def config(request: Request) -> Response:
        listing = await asyncio.to_thread(workspace.listing)
        # templates: what `tablebot new` offers, for a folder without a table
        return JSONResponse(
            {"table": table, "folder": workspace.root.name, "templates": list(TEMPLATES), "lang": lang, **listing},
            headers={"Cache-Control": "no-store"},
        )

    async def upload_trace(request: Request) -> Response:
        """A trace file from the user's computer (the body), size-limited while it arrives."""
        name = request.query_params.get("name", "uploaded trace")[:200]
        body = bytearray()
        try:
            async for chunk in request.stream():
                body += chunk
                if len(body) > MAX_PLAYER_TRACE_BYTES:
                    return JSONResponse(
                        ErrorMsg(
                            f"the trace is larger than {MAX_PLAYER_TRACE_BYTES:,} bytes", hint="cut the run shorter"
                        ).data(),
                        status_code=413,
                    )
        except ClientDisconnect:  # the tab closed or reloaded mid-upload: nobody is left to answer
            log.warning(
                "an uploaded trace (%s) was cut off after %s: the page closed the connection, nothing was read",
                terminal(name),
                _of_bytes(len(body), request.headers.get("content-length")),
            )
            return Response(status_code=400)
        try:
            lines = await asyncio.to_thread(read_trace_bytes, bytes(body), name)
        except TableBotError as exc:
            return JSONResponse(ErrorMsg(str(exc)).data(), status_code=400)
        except Exception:  # a bug: the page gets the studio's words, the terminal the traceback
            log.exception("an uploaded trace failed")
            return JSONResponse(ErrorMsg(INTERNAL).data(), status_code=500)
        return JSONResponse(TraceMsg(name, trace_columns(lines)).data())

    async def socket(websocket: WebSocket) -> None:
        await websocket.accept(subprotocol(websocket.scope))  # the page's key was checked by the gate
        if len(hub.sessions) >= tabs.most:
            await tabs.turn_away(websocket)
            return
        lock = asyncio.Lock()

        async def send(message: dict[str, Any]) -> None:
            async with lock:
                if websocket.application_state != WebSocketState.CONNECTED:
                    raise Gone
                try:
                    await websocket.send_text(json.dumps(message, separators=(",", ":")))
                except (WebSocketDisconnect, RuntimeError, OSError) as exc:  # the tab went away mid-send
                    raise Gone from exc

        session = Session(workspace, hub, send, language_of(websocket.query_params.get("lang")))
        hub.sessions.add(session)
        ticker = asyncio.create_task(_frames(session))
        try:
            while True:
                message = await websocket.receive()
                if message["type"] == "websocket.disconnect":
                    break
                if message.get("text") is None:
                    await session.error(N_("a message must be JSON text, not binary data"))
                    continue
                await _answer(session, message["text"])
        except (WebSocketDisconnect, Gone):
            pass
        finally:
            ticker.cancel()
            hub.sessions.discard(session)
            await asyncio.to_thread(session.close)
            await tabs.gone()

    routes = [
        Route("/", index),
        Route("/api/config", config),
        Route("/api/trace", upload_trace, methods=["POST"]),
        WebSocketRoute("/ws", socket),
        Route("/static/{path:path}", assets.endpoint, methods=["GET", "HEAD"]),
    ]
    return Gate(Starlette(routes=routes), access)


def _of_bytes(got: int, announced: str | None) -> str:
    """ "1,050 of 100,000 bytes" (or "1,050 bytes" when the upload did not say its length)."""
    return f"{got:,} of {int(announced):,} bytes" if announced and announced.isdigit() else f"{got:,} bytes"


@dataclass
class Tabs:
    """How many tabs a studio serves at once (each has a live robot: a thread), whether the terminal has
    been told of a tab turned away since a place last came free (one line, not one per tab), and whether
    the memory of tabs that went is about to be given back."""

    most: int
    told: bool = False
    tidying: bool = False

    async def gone(self) -> None:
        """A tab went: a place is free, and the memory it used goes back to the system."""
        self.told = False
        await self.tidy()

    async def tidy(self) -> None:
        """Give back the memory of connections that closed: once for those that close together (a browser
        window of tabs), since it holds every thread for a moment."""
        if self.tidying:
            return
        self.tidying = True
        try:
            await asyncio.sleep(TIDY_AFTER_S)
        finally:
            self.tidying = False
        await asyncio.to_thread(give_back_memory)

    async def turn_away(self, websocket: WebSocket) -> None:
        """The page shows why in its banner: an error, answered to every message (the socket stays open,
        since the page reads a closed one as the studio stopping)."""
        tabs = f"{self.most} tab{'s' if self.most != 1 else ''}"
        if not self.told:
            log.warning(
                "refused a tab: %s %s open already, the most one studio serves at once (close one of "
                "them in the browser)",
                tabs,
                "are" if self.most != 1 else "is",
            )
            self.told = True
        refusal = json.dumps(
            ErrorMsg(
                f"this studio already has {tabs} open, the most it serves at once: close one "
                "of them, then reload this tab"
            ).data()
        )
        try:
            await websocket.send_text(refusal)
            while (await websocket.receive())["type"] != "websocket.disconnect":
                await websocket.send_text(refusal)
        except (WebSocketDisconnect, RuntimeError, OSError):  # the tab went while being told
            pass
        await self.tidy()


async def _answer(session: Session, text: str) -> None:
    """One message from the page; nothing it sends can end the connection or the server."""
    if len(text) > MAX_MESSAGE_BYTES:
        await session.error(N_("message too large ({n:,} characters)", n=len(text)))
        return
    try:
        message = json.loads(text)
    except json.JSONDecodeError as exc:
        await session.error(N_("not JSON: {why}", why=exc.msg))
        return
    except RecursionError:
        await session.error(N_("the message is nested too deeply: the page never sends such a message"))
        return
    try:
        await session.handle(message)
    except Gone:
        raise
    except Exception:  # a bug: the page is told so, the terminal gets the traceback, the server goes on
        log.exception("a message from the page failed")
        await session.error(INTERNAL)


async def _frames(session: Session) -> None:
    """The live robot's frames, until the tab goes; a failure is reported once and ends only the frames."""
    while True:
        await asyncio.sleep(FRAME_S)
        try:
            await session.frame()
        except Gone:
            return
        except Exception:
            log.exception("the live view stopped")
            with contextlib.suppress(Exception):  # the socket itself may be what failed
                await session.error("the live view stopped: " + INTERNAL)
            return


def server(app: Gate, access: Access, log_level: str = "warning") -> uvicorn.Server:
    """A uvicorn server for the studio (run it with ``sockets=[...]``); the token never reaches its logs."""
    config = uvicorn.Config(
        app,
        log_level=log_level,
        access_log=log_level in ("info", "debug", "trace"),
        ws_max_size=MAX_MESSAGE_BYTES,
        lifespan="off",
    )
    hide_token_in_logs(access.token)  # uvicorn configured its loggers just now, in Config()
    return uvicorn.Server(config)


class Background:
    """The studio served from a thread (tests, benchmarks): ``url`` (with its token) while running,
    ``origin`` and ``headers`` (what its own page sends: its Origin and token header) for other clients,
    :meth:`stop` to end."""

    def __init__(
        self,
        root: Path,
        table: str | None = None,
        host: str = "127.0.0.1",
        port: int = 0,
        log_level: str = "warning",
        max_tabs: int = MAX_TABS,
        lang: str | None = None,
    ) -> None:
        import socket

        self.sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.sock.bind((host, port))
        self.sock.listen(64)
        self.access = Access.serving(host, self.sock.getsockname()[1])
        self.origin = f"http://{host}:{self.access.port}"
        self.url = self.access.url(host)
        self.headers = {"Origin": self.origin, TOKEN_HEADER: self.access.token}
        self.server = server(create_app(root, self.access, table, max_tabs, lang=lang), self.access, log_level)
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
