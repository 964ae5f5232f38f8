"""Who may talk to the studio: only the page it served. Every HTTP request and WebSocket upgrade passes
:class:`Gate`, which answers 403 before any route runs unless the ``Host`` is a name the studio serves,
the ``Origin`` (when the browser sends one) is the studio's own, the request was not started by another
site, and (except for the page's own files) it carries the secret token made at this start.

The rules follow Jupyter's server (``jupyter_server/base/handlers.py``: ``check_host``, ``check_origin``,
token login): a page on another origin cannot read or change the folder, and DNS rebinding (a foreign name
that resolves to 127.0.0.1) meets the ``Host`` check. Logs show the token as ``[token]``, however it is
percent-encoded.

Where the token lives, on a machine other users' pages and servers share: not in a cookie. Browsers keep
cookies per host name, not per port, so a cookie of 127.0.0.1 goes to every server on 127.0.0.1 (another
user's program on another port would read the token from its requests), and a page on another port can
plant cookies of the same name. The token reaches the page once, in the address the studio prints
(``/?token=...``, opened through :mod:`.launch`'s private file); the page keeps it in ``sessionStorage``
(one per origin, that is per port, and per tab) and takes it out of the address bar and history at once.
It sends it with every API request in the ``X-Tablebot-Token`` header and with the WebSocket as a
subprotocol (``tablebot-token.<token>``, beside ``tablebot-studio``, the one the server accepts), so the
gate checks it on the upgrade, before any route runs. The page itself and its scripts and styles
(``/``, ``/static/...``) hold no secret and are served without the token; a page without one shows the
studio's refusal, which says how to get in.
"""

from __future__ import annotations

import ipaddress
import logging
import re
import secrets
import socket
from collections.abc import Awaitable, Callable, MutableMapping
from dataclasses import dataclass, field
from typing import Any

Scope = MutableMapping[str, Any]
Message = MutableMapping[str, Any]
Receive = Callable[[], Awaitable[Message]]
Send = Callable[[Message], Awaitable[None]]
ASGIApp = Callable[[Scope, Receive, Send], Awaitable[None]]

LOCAL_NAMES = ("127.0.0.1", "localhost", "[::1]")
WILDCARDS = ("0.0.0.0", "::", "[::]")
#: Sec-Fetch-Site values of requests the studio's own page makes (or the user typed): anything else was
#: started by another page, even one on this machine's other ports ("same-site").
OWN_FETCHES = ("same-origin", "none")
#: The header that carries the token on the page's requests, and the WebSocket subprotocols: the one the
#: server accepts (never the one holding the token, which stays out of the answer) and the token's prefix.
TOKEN_HEADER = "x-tablebot-token"
SUBPROTOCOL = "tablebot-studio"
TOKEN_PROTOCOL = "tablebot-token."
#: What the page is made of: files that hold no secret, served without the token (to GET and HEAD only).
PUBLIC_PATHS = ("/", "/static/")
#: Sent with every answer: no sniffing JSON as script, no framing, no address (with its token) in a Referer.
HEADERS = [(b"x-content-type-options", b"nosniff"), (b"x-frame-options", b"DENY"), (b"referrer-policy", b"no-referrer")]


def host_name(address: str) -> str:
    """An address as it appears in a Host header or URL (an IPv6 literal in brackets), lower case."""
    address = address.strip().lower()
    if ":" in address and not address.startswith("["):
        return f"[{address}]"
    return address


def _is_ip(name: str) -> bool:
    try:
        ipaddress.ip_address(name.strip("[]"))
    except ValueError:
        return False
    return True


@dataclass(frozen=True)
class Access:
    """The studio's key and the names it answers to, made once per start."""

    port: int
    names: frozenset[str]  # host names as in a Host header (IPv6 in brackets), lower case
    any_ip: bool = False  # serving every interface: any IP literal names this machine too
    token: str = field(default_factory=lambda: secrets.token_urlsafe(32), repr=False)

    @classmethod
    def serving(cls, address: str, port: int, token: str | None = None) -> Access:
        """The access rules for a studio bound to ``address`` (as given to ``--host``) and ``port``."""
        names = set(LOCAL_NAMES)
        wildcard = address.strip() in WILDCARDS
        if wildcard:  # what people on the network type: this machine's names (IP literals are allowed below)
            hostname = socket.gethostname().lower()
            names |= {hostname, f"{hostname}.local", socket.getfqdn().lower()}
        else:
            names.add(host_name(address))
        extra = {"token": token} if token else {}
        return cls(port, frozenset(names), wildcard, **extra)

    def url(self, shown: str, query: str = "") -> str:
        """The address to print and open: the studio's page with the token."""
        return f"http://{host_name(shown)}:{self.port}/?token={self.token}" + (f"&{query}" if query else "")

    # --- the checks -----------------------------------------------------------------------------------

    def serves(self, host: str) -> bool:
        """Whether ``host`` (a Host header) names this studio: a served name and the studio's port."""
        name, _, port = host.lower().rpartition(":")
        if not name or "]" in port:  # no port given (port 80), or a bare IPv6 literal
            name, port = host.lower(), "80"
        if port != str(self.port):
            return False
        return name in self.names or (self.any_ip and _is_ip(name))

    def has_token(self, given: list[str]) -> bool:
        """Whether any of the tokens ``given`` (from headers, subprotocols or the address) is this start's."""
        return any(secrets.compare_digest(value.encode(), self.token.encode()) for value in given)

    def refusal(self, scope: Scope) -> str | None:
        """Why the request is refused (the studio's words), or None to let it through."""
        headers = {k.decode("latin-1").lower(): v.decode("latin-1") for k, v in scope.get("headers", [])}
        host = headers.get("host", "")
        if not self.serves(host):
            return (
                f"refused: this studio does not answer to the address {host[:100]!r} "
                "(open the address that tablebot studio printed)"
            )
        origin = headers.get("origin")
        if origin is not None and origin.lower() != f"http://{host.lower()}":
            return f"refused: a page from {origin[:100]!r} may not use this studio"
        public = _public(scope)
        # a link from anywhere may lead to the page (it holds nothing); a frame of it, never
        landing = public and scope.get("path") == "/" and headers.get("sec-fetch-dest", "document") == "document"
        fetch_site = headers.get("sec-fetch-site")
        if fetch_site is not None and fetch_site not in OWN_FETCHES and not landing:
            return f"refused: the request was started by another page ({fetch_site[:20]})"
        if public or self.has_token(given_tokens(scope)):
            return None
        return (
            "refused: the studio's key is missing or out of date: open the address that tablebot "
            "studio printed (…/?token=…); each start makes a new one"
        )


def _public(scope: Scope) -> bool:
    """The page or one of its files (no secret in them), fetched, not posted."""
    path = str(scope.get("path", ""))
    return (
        scope["type"] == "http"
        and scope.get("method") in ("GET", "HEAD")
        and (path == PUBLIC_PATHS[0] or path.startswith(PUBLIC_PATHS[1]))
    )


def given_tokens(scope: Scope) -> list[str]:
    """The tokens a request carries: every ``X-Tablebot-Token`` header, and for a WebSocket upgrade every
    offered subprotocol ``tablebot-token.<token>`` (a browser's WebSocket can set no header)."""
    given = []
    for key, value in scope.get("headers", []):
        if key.lower() == TOKEN_HEADER.encode():
            given.append(value.decode("latin-1").strip())
    if scope["type"] == "websocket":
        given += [p[len(TOKEN_PROTOCOL) :] for p in scope.get("subprotocols", []) if p.startswith(TOKEN_PROTOCOL)]
    return given


def subprotocol(scope: Scope) -> str | None:
    """The subprotocol to accept a WebSocket with: the studio's, when the page offered it (a browser fails a
    connection whose offered subprotocols the server ignores), else none."""
    return SUBPROTOCOL if SUBPROTOCOL in scope.get("subprotocols", []) else None


class Gate:
    """ASGI middleware: every request and WebSocket upgrade is checked by :meth:`Access.refusal` first,
    and every answer gets :data:`HEADERS`."""

    def __init__(self, app: ASGIApp, access: Access) -> None:
        self.app = app
        self.access = access

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] not in ("http", "websocket"):
            await self.app(scope, receive, send)
            return
        reason = self.access.refusal(scope)
        if reason is not None:
            await _deny(scope, send, reason)
            return
        if scope["type"] == "websocket":
            await self.app(scope, receive, send)
            return

        async def with_headers(message: Message) -> None:
            if message["type"] == "http.response.start":
                message["headers"] = [*message.get("headers", []), *HEADERS]
            await send(message)

        await self.app(scope, receive, with_headers)


async def _deny(scope: Scope, send: Send, reason: str) -> None:
    """403 with the reason as plain text; a WebSocket upgrade is refused before it is accepted.

    (Not the ASGI "websocket.http.response" extension: uvicorn's sans-I/O WebSocket protocol logs that
    as a handshake never completed.)"""
    body = (reason + "\n").encode("utf-8")
    headers = [
        (b"content-type", b"text/plain; charset=utf-8"),
        (b"content-length", str(len(body)).encode()),
        (b"cache-control", b"no-store"),
        *HEADERS,
    ]
    if scope["type"] == "http":
        await send({"type": "http.response.start", "status": 403, "headers": headers})
        await send({"type": "http.response.body", "body": body})
    else:  # an upgrade closed before acceptance: the server answers 403 (a page cannot read the reason anyway)
        await send({"type": "websocket.close", "code": 1008})


def spellings(token: str) -> re.Pattern[str]:
    """Every way ``token`` can be written in an address: each character as it is or percent-encoded, once or
    more (``%41``, ``%2541``; either case of hex digit), since the server decodes the query before comparing."""
    parts = []
    for char in token:
        hex_digits = "".join(f"[{d.lower()}{d.upper()}]" for d in f"{ord(char):02x}")
        parts.append(f"(?:{re.escape(char)}|%(?:25)*{hex_digits})")
    return re.compile("".join(parts))


class HideToken(logging.Filter):
    """Writes every studio token of this process as ``[token]`` in log records (uvicorn's request lines
    show query strings as they came, percent-encoding and all)."""

    def __init__(self) -> None:
        super().__init__()
        self.tokens: dict[str, re.Pattern[str]] = {}

    def add(self, token: str) -> None:
        self.tokens.setdefault(token, spellings(token))

    def _hide(self, text: str) -> str:
        for pattern in self.tokens.values():
            text = pattern.sub("[token]", text)
        return text

    def filter(self, record: logging.LogRecord) -> bool:
        if isinstance(record.msg, str):
            record.msg = self._hide(record.msg)
        if isinstance(record.args, tuple):
            record.args = tuple(self._hide(a) if isinstance(a, str) else a for a in record.args)
        return True


_HIDE = HideToken()


def hide_token_in_logs(token: str) -> None:
    """Hide ``token`` in uvicorn's logs (call after uvicorn has configured its loggers)."""
    _HIDE.add(token)
    for name in ("uvicorn.access", "uvicorn.error", "uvicorn"):
        logger = logging.getLogger(name)
        if _HIDE not in logger.filters:
            logger.addFilter(_HIDE)
