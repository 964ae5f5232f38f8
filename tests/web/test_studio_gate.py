"""The studio's gate (issue 18 section 1, issue 33 section 3), over real HTTP and WebSocket connections to a
real server on loopback: the Host, the Origin, who started the request and the token are checked before any
route runs. The token travels in a header, or for a WebSocket as a subprotocol, never in a cookie; the page
and its files, which hold no secret, are served without it. The same from a page in a real Chromium:
test_studio_attacks.py and test_studio_shared_pc.py.
"""

from __future__ import annotations

import socket
import urllib.request
from collections.abc import Iterator

import pytest

from studio_helpers import bumberbot, http, served
from tablebot.web.access import TOKEN_HEADER
from tablebot.web.app import Background


@pytest.fixture(scope="module")
def studio(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Background]:
    yield from served(bumberbot(tmp_path_factory.mktemp("gate")))


def upgrade_status(server: Background, headers: dict[str, str]) -> int:
    """The status a WebSocket upgrade with ``headers`` gets (101 when accepted)."""
    return upgrade(server, headers)[0]


def upgrade(server: Background, headers: dict[str, str]) -> tuple[int, str | None]:
    """The status a WebSocket upgrade with ``headers`` gets and the subprotocol accepted, its bytes written by
    hand so that the Host header is exactly the one given."""
    lines = [
        "GET /ws HTTP/1.1",
        "Upgrade: websocket",
        "Connection: Upgrade",
        "Sec-WebSocket-Version: 13",
        "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==",
    ]
    headers = {"Host": f"127.0.0.1:{server.access.port}", **headers}
    lines += [f"{key}: {value}" for key, value in headers.items()]
    with socket.create_connection(("127.0.0.1", server.access.port), timeout=10) as conn:
        conn.sendall(("\r\n".join(lines) + "\r\n\r\n").encode("latin-1"))
        answer = conn.makefile("rb")
        status = int(answer.readline().split()[1])
        protocol = None
        while line := answer.readline().decode("latin-1").strip():
            name, _, value = line.partition(":")
            if name.lower() == "sec-websocket-protocol":
                protocol = value.strip()
    return status, protocol


def test_every_api_needs_the_token_the_pages_files_do_not(studio: Background) -> None:
    """The page, its scripts and styles hold no secret: served without the token, so an address without it
    shows the studio's refusal in the page. What reads or changes the folder needs it, in its header."""
    origin_only = {"Origin": studio.origin}
    for path in ("", "static/js/studio/main.js", "static/js/lib/key.js", "static/studio.css"):
        assert http(studio, path, origin_only)[0] == 200, path
    status, body = http(studio, "api/config", origin_only)
    assert status == 403 and b"the studio's key is missing" in body
    assert http(studio, "api/config")[0] == 200  # with the page's header
    wrong = {**studio.headers, TOKEN_HEADER: "x" * len(studio.access.token)}
    assert http(studio, "api/config", wrong)[0] == 403
    cookie = {"Origin": studio.origin, "Cookie": f"tablebot-studio-{studio.access.port}={studio.access.token}"}
    assert http(studio, "api/config", cookie)[0] == 403  # the old cookie opens nothing any more
    assert http(studio, "api/trace?name=t.jsonl", origin_only, b'{"tick":0,"state":1}\n')[0] == 403
    assert http(studio, f"api/config?token={studio.access.token}", origin_only)[0] == 403  # never from the address
    assert http(studio, "static/js/studio/main.js", origin_only, b"x")[0] in (403, 405)  # files are only fetched
    assert upgrade_status(studio, origin_only) == 403
    assert upgrade_status(studio, studio.headers) == 101


def test_a_websocket_carries_the_token_as_a_subprotocol(studio: Background) -> None:
    """A browser's WebSocket can set no header: the page offers the token as a subprotocol beside the
    studio's, and the server accepts the studio's (the token stays out of its answer)."""
    token = studio.access.token
    offer = {"Origin": studio.origin, "Sec-WebSocket-Protocol": f"tablebot-studio, tablebot-token.{token}"}
    assert upgrade(studio, offer) == (101, "tablebot-studio")
    other = token[:-1] + ("A" if token[-1] != "A" else "B")
    for wrong in (
        "tablebot-studio, tablebot-token.",
        f"tablebot-studio, tablebot-token.{other}",
        f"tablebot-studio, {token}",
        "tablebot-studio",
    ):
        assert upgrade(studio, {**offer, "Sec-WebSocket-Protocol": wrong})[0] == 403, wrong
    assert upgrade(studio, {**offer, "Origin": "http://127.0.0.1:1"})[0] == 403  # the Origin is checked as well


def test_no_answer_sets_a_cookie(studio: Background) -> None:
    """A 127.0.0.1 cookie would go to every port of 127.0.0.1: the studio sets none (the page keeps the token)."""
    request = urllib.request.Request(studio.url, headers={"Sec-Fetch-Site": "cross-site"})  # a link elsewhere
    with urllib.request.urlopen(request) as reply:
        assert reply.headers["Referrer-Policy"] == "no-referrer" and reply.headers["X-Frame-Options"] == "DENY"
        assert "frame-ancestors 'none'" in reply.headers["Content-Security-Policy"]
        assert reply.headers.get_all("Set-Cookie") is None
    for path in ("api/config", "static/js/lib/key.js"):
        with urllib.request.urlopen(urllib.request.Request(f"{studio.origin}/{path}", headers=studio.headers)) as reply:
            assert reply.headers.get_all("Set-Cookie") is None, path


@pytest.mark.parametrize(
    "host",
    ["attacker.example:{port}", "attacker.example", "127.0.0.1:1", "localhost.evil:{port}", "10.0.0.8:{port}", ""],
)
def test_a_host_the_studio_does_not_serve_is_refused_before_any_route(studio: Background, host: str) -> None:
    """DNS rebinding: a foreign name resolving to 127.0.0.1 reaches the server with its own Host header."""
    headers = {
        **studio.headers,
        "Host": host.format(port=studio.access.port),
        "Origin": "http://" + host.format(port=studio.access.port),
    }
    for path in ("", "api/config", "static/js/studio/main.js", "no/such/route"):
        status, body = http(studio, path, headers)
        assert status == 403 and b"does not answer to the address" in body, (host, path)
    assert upgrade_status(studio, headers) == 403


@pytest.mark.parametrize("name", ["127.0.0.1", "localhost", "LOCALHOST"])
def test_the_local_names_are_served(studio: Background, name: str) -> None:
    host = f"{name}:{studio.access.port}"
    assert http(studio, "api/config", {**studio.headers, "Host": host, "Origin": f"http://{host}"})[0] == 200


@pytest.mark.parametrize(
    "origin",
    ["http://attacker.example", "http://127.0.0.1:1", "null", "https://127.0.0.1:{port}", "http://localhost:{port}"],
)
def test_a_foreign_origin_is_refused(studio: Background, origin: str) -> None:
    headers = {**studio.headers, "Origin": origin.format(port=studio.access.port)}
    status, body = http(studio, "api/config", headers)
    assert status == 403 and b"may not use this studio" in body
    assert http(studio, "api/trace?name=t.jsonl", headers, b'{"tick":0,"state":1}\n')[0] == 403
    assert upgrade_status(studio, headers) == 403


@pytest.mark.parametrize("site", ["same-site", "cross-site"])
def test_a_request_another_page_started_is_refused(studio: Background, site: str) -> None:
    """A page on 127.0.0.1:OTHER that had the token still could not use it from an <img> or <iframe> (no
    Origin header); Sec-Fetch-Site tells. Only the page itself may be reached by a link from elsewhere."""
    token = {TOKEN_HEADER: studio.access.token, "Sec-Fetch-Site": site}
    status, body = http(studio, "api/config", token)
    assert status == 403 and b"started by another page" in body
    assert http(studio, "static/js/studio/main.js", token)[0] == 403
    assert http(studio, "", {"Sec-Fetch-Site": site})[0] == 200  # the page, which holds nothing
    assert http(studio, "", {"Sec-Fetch-Site": site, "Sec-Fetch-Dest": "document"})[0] == 200  # a link
    assert http(studio, "", {"Sec-Fetch-Site": site, "Sec-Fetch-Dest": "iframe"})[0] == 403  # a frame: never
