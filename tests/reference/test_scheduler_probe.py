"""A peer on the scheduler's port that is not a Dask scheduler: one line, within the timeout.

Dask's client trusts the peer: one that accepts and never answers kept it waiting for ever, and a
length header of 2**40 bytes made it try to allocate that much (docs/bad-input.md). Each fake peer
here listens on 127.0.0.1 in a thread of the test and is closed when the test ends.
"""

from __future__ import annotations

import socket
import struct
import threading
import time

import pytest

from reference.errors import SpecrefError
from reference.tasks import dask_client, probe_scheduler

REPLIES = {
    "silent": None,
    "http": b"HTTP/1.1 200 OK\r\nContent-Length: 5\r\n\r\nhello",
    "random bytes": bytes(range(256)) * 4,
    "a 2**40-byte frame": struct.pack("Q", 16) + struct.pack("Q", 1) + struct.pack("Q", 2**40),
    "closes at once": b"",
}
MESSAGES = {
    "silent": "sent no Dask handshake in time",
    "http": "not a Dask scheduler (it announced",
    "random bytes": "not a Dask scheduler (it announced",
    "a 2**40-byte frame": "not a Dask scheduler (frames too large)",
    "closes at once": "closed the connection",
}


@pytest.fixture
def peer(request):
    reply = REPLIES[request.param]
    server = socket.create_server(("127.0.0.1", 0))
    server.settimeout(0.05)  # so that the loop sees the test's end
    held, done = [], threading.Event()

    def serve():
        while not done.is_set():
            try:
                conn, _ = server.accept()
            except OSError:  # a timeout: look at done again
                continue
            if reply == b"":
                conn.close()
                continue
            held.append(conn)
            if reply:
                conn.sendall(reply)

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    yield request.param, f"tcp://127.0.0.1:{server.getsockname()[1]}"
    done.set()
    thread.join(timeout=5)
    server.close()
    for conn in held:
        conn.close()


@pytest.mark.parametrize("peer", list(REPLIES), indirect=True)
def test_a_peer_that_is_not_a_scheduler_is_one_line_within_the_timeout(peer):
    kind, address = peer
    start = time.monotonic()
    with pytest.raises(SpecrefError) as refused, dask_client(address, timeout=1.0):
        pass
    assert time.monotonic() - start < 5.0
    message = str(refused.value)
    assert message.startswith(f"--scheduler {address}: ")
    assert MESSAGES[kind] in message
    assert "\n" not in message


def test_the_probe_reads_a_real_handshake():
    # what a scheduler sends first, as distributed packs it: one frame, a msgpack'd dict
    from distributed.protocol.core import dumps
    from distributed.protocol.utils import pack_frames

    handshake = {"compression": None, "python": (3, 11, 7), "pickle-protocol": 5}
    message = pack_frames(dumps(handshake))
    server = socket.create_server(("127.0.0.1", 0))

    def serve():
        conn, _ = server.accept()
        conn.sendall(struct.pack("Q", len(message)) + message)
        conn.recv(1)
        conn.close()

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    try:
        found = probe_scheduler(f"tcp://127.0.0.1:{server.getsockname()[1]}", 2.0)
    finally:
        server.close()
        thread.join(timeout=5)
    assert found["pickle-protocol"] == 5
