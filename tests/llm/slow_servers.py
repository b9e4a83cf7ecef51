"""Servers that answer too slowly, for the client's deadlines (real sockets on 127.0.0.1).

SilentServer accepts every connection and never answers (a hung server): `connections` counts them.
TrickleServer answers a chat completion correctly but writes its body one byte every `pace_s`, which
no per-read timeout ever trips: `bytes_sent` and `body_bytes` say how much of it went out.
"""

from __future__ import annotations

import contextlib
import json
import socket
import threading
from typing import Self

COMPLETION = {"id": "chatcmpl-slow", "object": "chat.completion", "created": 0, "model": "slow",
              "choices": [{"index": 0, "finish_reason": "stop",
                           "message": {"role": "assistant", "content": "A late answer."}}],
              "usage": {"prompt_tokens": 5, "completion_tokens": 3, "total_tokens": 8}}


class _Listener:
    def __init__(self) -> None:
        self._socket = socket.create_server(("127.0.0.1", 0))
        self._stopping = threading.Event()
        self._open: list[socket.socket] = []
        self.connections = 0
        threading.Thread(target=self._accept, daemon=True).start()

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self._socket.getsockname()[1]}/v1"

    def _accept(self) -> None:
        while not self._stopping.is_set():
            try:
                connection, _ = self._socket.accept()
            except OSError:
                return
            self.connections += 1
            self._open.append(connection)
            threading.Thread(target=self.serve, args=(connection,), daemon=True).start()

    def serve(self, connection: socket.socket) -> None:
        """Silent: read what comes, never answer."""
        with contextlib.suppress(OSError):
            while connection.recv(65536) and not self._stopping.is_set():
                pass

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self._stopping.set()
        self._socket.close()
        for connection in self._open:
            with contextlib.suppress(OSError):
                connection.shutdown(socket.SHUT_RDWR)


class SilentServer(_Listener):
    pass


class TrickleServer(_Listener):
    def __init__(self, pace_s: float = 0.01) -> None:
        super().__init__()
        self.pace_s, self.bytes_sent = pace_s, 0
        self.body = json.dumps(COMPLETION).encode()
        self.body_bytes = len(self.body)

    def serve(self, connection: socket.socket) -> None:
        with contextlib.suppress(OSError):
            request = b""
            while b"\r\n\r\n" not in request:
                request += connection.recv(65536)
            head, _, rest = request.partition(b"\r\n\r\n")
            length = int(next((line.split(b":")[1] for line in head.split(b"\r\n")
                               if line.lower().startswith(b"content-length")), b"0"))
            while len(rest) < length:
                rest += connection.recv(65536)
            connection.sendall(b"HTTP/1.1 200 OK\r\nContent-Type: application/json\r\n"
                               b"Content-Length: %d\r\n\r\n" % self.body_bytes)
            for k in range(self.body_bytes):
                if self._stopping.wait(self.pace_s):
                    return
                connection.sendall(self.body[k:k + 1])
                self.bytes_sent += 1
