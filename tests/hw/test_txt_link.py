"""The online protocol's client link against the fake TXT, and unmodified ftrobopy against the same fake
(a second, independent client keeps the fake honest)."""

from __future__ import annotations

import http.server
import os
import signal
import socket
import socketserver
import struct
import threading
import time
import warnings

import pytest

from tablebot.hw.txt import protocol as wire
from tablebot.hw.txt.link import TxtLink, find_controller
from tablebot.hw.txt.protocol import Command
from tablebot.loop import LinkLost
from txt_fake import FakeTxt

pytestmark = [pytest.mark.realtime]


def numbered(n: int) -> tuple[list[int], list[int]]:
    """Inputs that say which exchange they answer: I1 = n, C1 = 2n."""
    return [n, 0, 0, 0, 0, 0, 0, 0], [2 * n, 0, 0, 0]


def online(fake: FakeTxt, timeout_s: float = 0.5) -> TxtLink:
    link = TxtLink("127.0.0.1", fake.port, reply_timeout_s=timeout_s)
    link.connect()
    link.start_online()
    link.update_config(wire.Config())
    return link


def test_the_wire_sizes_are_the_headers_c_struct_sizes() -> None:
    assert wire.REQUEST_SIZE[Command.UPDATE_CONFIG] == 96 and wire.REQUEST_SIZE[Command.EXCHANGE_DATA] == 60
    assert wire.REPLY_SIZE[Command.EXCHANGE_DATA] == 80 and wire.REPLY_SIZE[Command.QUERY_STATUS] == 24
    assert len(wire.start_online("x")) == 68
    assert wire.exchange([600, -3, 0, 0, 0, 0, 0, 512])[4:20] == struct.pack("<8h", 512, 0, 0, 0, 0, 0, 0, 512)


def test_status_config_and_exchanges_round_trip_through_the_fake() -> None:
    with FakeTxt(numbered, device="TXT-4711", version=0x04060600) as fake:
        link = TxtLink("127.0.0.1", fake.port)
        link.connect()
        status = link.query_status()
        link.start_online("tablebot")
        config = wire.Config(
            motors=(True, False, True, True),
            inputs=(wire.InputConfig(wire.InputMode.ULTRASONIC, False),) + (wire.InputConfig(),) * 7,
        )
        link.update_config(config)
        replies = [link.exchange([64 * i, 0, 0, 0, 0, 0, 0, 0]) for i in range(5)]
        link.stop_online()
        link.close()
        time.sleep(0.05)
    assert (status.device, status.version_text) == ("TXT-4711", "4.6.6")
    fields = fake.requests("UpdateConfig")[0].fields
    assert fields["motors"] == [1, 0, 1, 1] and fields["inputs"][0] == (3, 0) and fields["inputs"][1] == (1, 1)
    assert fields["config_id"] == 1
    assert [r.universal[0] for r in replies] == [0, 1, 2, 3, 4]
    assert [r.counter_values[0] for r in replies] == [0, 2, 4, 6, 8]
    assert [r.fields["pwm"][0] for r in fake.requests("ExchangeData")] == [0, 64, 128, 192, 256]
    assert fake.names() == ["QueryStatus", "StartOnline", "UpdateConfig", *["ExchangeData"] * 5, "StopOnline", "closed"]


def test_a_reply_left_unread_is_skipped_so_the_next_exchange_gets_its_own_reply() -> None:
    """As after Ctrl-C in the middle of a reply: the stream stays in step."""
    with FakeTxt(numbered, period_s=0.02) as fake:
        link = online(fake)
        assert link.send_best_effort(Command.EXCHANGE_DATA, wire.exchange([0] * 8), timeout_s=0.001)
        reply = link.exchange([0] * 8)
        link.close()
    assert reply.universal[0] == 1  # the second exchange's reply, not the first's


def test_keep_alive_sends_a_query_status_only_after_a_second_of_silence() -> None:
    with FakeTxt() as fake:
        link = online(fake)
        assert not link.keep_alive(idle_s=1.0)
        link.last_reply -= 1.5
        assert link.keep_alive(idle_s=1.0)
        link.close()
        time.sleep(0.05)
    assert fake.names().count("QueryStatus") == 1


@pytest.mark.parametrize(
    ("fault", "message"),
    [
        ("silent", "no answer from"),
        ("garbage", "malformed reply"),
        ("wrong_id", "wrong response id 0xBAC9723E (expected 0x4EEFAC41)"),
        ("close", "closed the connection"),
    ],
)
def test_every_fault_is_link_lost_with_a_sentence(fault: str, message: str) -> None:
    with FakeTxt(fault=(fault, 2)) as fake:
        link = online(fake, timeout_s=0.05)
        link.exchange([0] * 8)
        link.exchange([0] * 8)
        with pytest.raises(LinkLost, match=message.replace("(", r"\(").replace(")", r"\)")):
            link.exchange([0] * 8)
        link.close()


def test_after_a_malformed_reply_the_link_refuses_to_trust_replies_but_still_sends_the_stop() -> None:
    with FakeTxt(fault=("garbage", 1)) as fake:
        link = online(fake, timeout_s=0.05)
        link.exchange([512] * 8)
        with pytest.raises(LinkLost):
            link.exchange([512] * 8)
        with pytest.raises(LinkLost, match="cannot be trusted"):
            link.exchange([512] * 8)
        assert link.send_best_effort(Command.EXCHANGE_DATA, wire.exchange([0] * 8), timeout_s=0.05)
        link.close()
        time.sleep(0.05)
    assert fake.requests("ExchangeData")[-1].fields["pwm"] == [0] * 8


def test_connect_errors_say_where() -> None:
    with FakeTxt() as fake:
        port = fake.port
    with pytest.raises(LinkLost, match=f"cannot connect to 127.0.0.1:{port}"):
        TxtLink("127.0.0.1", port).connect(timeout_s=0.5)
    with pytest.raises(LinkLost, match=r"cannot find the controller no-such-txt\.invalid"):
        TxtLink("no-such-txt.invalid").connect(timeout_s=0.5)


class Listener:
    """Something else on the TXT's port at ``host``: an HTTP server (Python's own, which waits for a
    request line), or a server that answers whatever comes with an HTTP error at once, as many do."""

    def __init__(self, host: str, port: int, kind: str) -> None:
        if kind == "http":
            self.server: socketserver.BaseServer = http.server.ThreadingHTTPServer(
                (host, port), http.server.BaseHTTPRequestHandler
            )
        else:
            self.server = socketserver.ThreadingTCPServer((host, port), BadRequest)
        self.server.daemon_threads = True
        threading.Thread(target=self.server.serve_forever, daemon=True).start()

    def close(self) -> None:
        self.server.shutdown()
        self.server.server_close()


class BadRequest(socketserver.BaseRequestHandler):
    def handle(self) -> None:
        self.request.recv(64)
        self.request.sendall(b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n")


def test_auto_takes_the_first_address_that_answers_as_a_txt() -> None:
    """Loopback addresses only: an HTTP server on .2, one that answers garbage with an HTTP error on .3,
    nothing on .4, the fake TXT on .5 -- only .5 counts, and each of the others says what it did."""
    with FakeTxt(host="127.0.0.5") as fake:
        port = fake.port
        others = [Listener("127.0.0.2", port, "http"), Listener("127.0.0.3", port, "400")]
        try:
            hosts = ("127.0.0.2", "127.0.0.3", "127.0.0.4", "127.0.0.5")
            started = time.monotonic()
            found, tried = find_controller(hosts, port, timeout_s=0.3)
            took = time.monotonic() - started
            none, tried_none = find_controller(hosts[:3], port, timeout_s=0.3)
        finally:
            for other in others:
                other.close()
    assert found == "127.0.0.5" and none is None
    assert tried == tried_none
    assert tried[0].startswith("127.0.0.2: no answer from 127.0.0.2")
    assert tried[1] == (
        f"127.0.0.3: malformed reply from 127.0.0.3:{port}: QUERY_STATUS: "
        "wrong response id 0x50545448 (expected 0xBAC9723E)"
    )
    assert tried[2].startswith(f"127.0.0.4: cannot connect to 127.0.0.4:{port}")
    assert took < 1.0  # asked at once, not one after the other
    assert fake.names()[0] == "QueryStatus"


def test_a_request_goes_out_whole_even_when_ctrl_c_comes_in_the_middle_of_sending_it() -> None:
    """A real socket whose peer reads late, so that sendall blocks part way; SIGINT arrives then. The
    KeyboardInterrupt comes after the last byte went out, never between two pieces of a request."""
    payload = bytes(range(256)) * 16384  # 4 MiB: more than the socket buffers hold
    with socket.create_server(("127.0.0.1", 0)) as server:
        link = TxtLink("127.0.0.1", server.getsockname()[1])
        link.connect()
        peer, _ = server.accept()
        received = bytearray()

        def read_late() -> None:
            time.sleep(0.3)
            while len(received) < len(payload) and (chunk := peer.recv(1 << 16)):
                received.extend(chunk)

        reader = threading.Thread(target=read_late)
        reader.start()
        threading.Timer(0.1, os.kill, (os.getpid(), signal.SIGINT)).start()
        with pytest.raises(KeyboardInterrupt):
            link._send(payload, time.monotonic() + 10, Command.EXCHANGE_DATA)
            time.sleep(1)  # where the interrupt lands if the send was not cut
        reader.join(10)
        peer.close()
        link.close()
    assert bytes(received) == payload


def test_against_a_server_that_reads_each_request_with_one_recv_every_request_arrives_whole() -> None:
    """ftrobopy_server's reading (txt_fake single_recv): a stream of exchanges, every one a recv of its own."""
    with FakeTxt(numbered, period_s=0, single_recv=True) as fake:
        link = online(fake)
        replies = [link.exchange([i, 0, 0, 0, 0, 0, 0, 0]) for i in range(200)]
        link.stop_online()
        link.close()
        time.sleep(0.05)
    assert [r.universal[0] for r in replies] == list(range(200))
    assert all(r.whole for r in fake.requests()) and len(fake.requests("ExchangeData")) == 200


@pytest.mark.parametrize("single_recv", [False, True], ids=["txt", "ftrobopy_server"])
def test_unmodified_ftrobopy_sets_a_motor_and_reads_an_input_through_the_fake(
    capsys: pytest.CaptureFixture, single_recv: bool
) -> None:
    import ftrobopy  # a dev dependency (pyproject.toml): missing, this fails rather than skips

    with (
        FakeTxt(lambda n: ([0, 0, 1, 0, 0, 0, 0, 0], [0] * 4), i2c=True, single_recv=single_recv) as fake,
        warnings.catch_warnings(),
    ):
        warnings.simplefilter("ignore", DeprecationWarning)  # ftrobopy uses Thread.setDaemon
        txt = ftrobopy.ftrobopy("127.0.0.1", fake.port)
        motor = txt.motor(1)
        button = txt.input(3)
        motor.setSpeed(300)
        deadline = time.monotonic() + 3
        while not any(r.fields["pwm"][0] == 300 for r in fake.requests("ExchangeData")):
            assert time.monotonic() < deadline, "ftrobopy never sent the motor's speed"
            time.sleep(0.01)
        txt.updateWait()
        pressed = button.state()
        txt.stopOnline()
        time.sleep(0.05)
    assert pressed == 1
    config = fake.requests("UpdateConfig")[-1].fields
    assert config["motors"][0] == 1 and config["inputs"][2] == (1, 1)
    assert any(r.fields["pwm"][:2] == [300, 0] for r in fake.requests("ExchangeData"))
    assert "StopOnline" in fake.names() and all(r.whole for r in fake.requests())
    assert "TXT-fake" in capsys.readouterr().out  # ftrobopy prints what it connected to
