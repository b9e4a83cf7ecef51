"""A scripted OpenAI-compatible chat server on 127.0.0.1 for planner tests and the fake benchmark.

Real sockets, real HTTP: the planner under test talks to it through litellm exactly as it would to a
hosted provider (api_base = server.url), so nothing inside litellm is mocked. Answers come from a
FIFO script first, then from `default` (an Answer, or a callable (body, index) -> Answer). Every
request body is recorded for assertions, and two counters stand in for wall-clock bounds: `peak`
(the most requests in progress at once: concurrency) and `answered` (answers sent so far; one still
sitting out its delay is not, so a client that returned before it has timed out). `usage` carries
the server's prompt-size estimate (fake_answers.prompt_tokens); `listing`, when set, answers GET
/v1/models (fake_llama_cpp.py: whose server it is). A request with
"stream": true gets server-sent events (fake_stream.py: paced tokens, a held or dying stream);
`tokens_sent` and `streams_dropped` (streams the client closed early) count them.

    with FakeOpenAI() as server:
        server.script(http_error(500), ok(PLAN_JSON))
        ... planner(api_base=server.url) ...
        assert server.count == 2
"""

from __future__ import annotations

import argparse
import contextlib
import json
import socket
import sys
import threading
import time
from collections import Counter, deque
from collections.abc import Callable
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Self

from fake_answers import FAULTS, PLAN_JSON, Answer, context_overflow, faulty, http_error, ok, prompt_tokens
from fake_stream import generation_s, send_stream, streamed

__all__ = ["PLAN_JSON", "Answer", "FakeOpenAI"]

CHAT_PATHS = ("/v1/chat/completions", "/chat/completions")


def _completion_body(answer: Answer, body: dict) -> dict:
    model, tokens = body.get("model", ""), prompt_tokens(body)
    return {
        "id": "chatcmpl-fake", "object": "chat.completion", "created": int(time.time()), "model": model,
        "choices": [{"index": 0, "finish_reason": answer.finish_reason,
                     "message": {"role": "assistant", "content": answer.content}}],
        "usage": {"prompt_tokens": tokens, "completion_tokens": 10, "total_tokens": tokens + 10},
    }


def _error_body(status: int, message: str | None = None) -> dict:
    kind = {429: "rate_limit_exceeded", 401: "invalid_api_key"}.get(status, "server_error")
    return {"error": {"message": message or f"scripted HTTP {status}", "type": kind, "code": kind}}


class FakeOpenAI:
    """The server; use as a context manager, or start()/stop()."""

    def __init__(self, default: Answer | Callable[[dict, int], Answer] | None = None,
                 api_key: str | None = None, models: tuple[str, ...] | None = None,
                 context_window: int | None = None) -> None:
        """`api_key`: 401 without it; `models`: 404 for any other model; `context_window`: 400 above it."""
        self.default = default or ok()
        self.api_key, self.models = api_key, models
        self.gate = context_overflow(context_window) if context_window else None
        self.listing: dict | None = None  # GET /v1/models answers it (None: 404, as many servers do)
        self.requests: list[dict] = []
        self.paths: list[str] = []
        self.served: Counter[str] = Counter()  # answer kinds sent, e.g. {"ok": 9, "http_500": 1}
        self.in_progress = self.peak = self.answered = 0
        self.tokens_sent = self.streams_dropped = 0  # streaming: tokens written; streams closed early
        self._script: deque[Answer] = deque()
        self._lock = threading.Lock()
        self._stopping = threading.Event()
        self._connections: set[socket.socket] = set()  # open keep-alive connections, closed by stop()
        self._server = ThreadingHTTPServer(("127.0.0.1", 0), type("Handler", (_Handler,), {"fake": self}))
        self._server.daemon_threads = True
        self._thread = threading.Thread(target=self._server.serve_forever, kwargs={"poll_interval": 0.02},
                                        daemon=True)

    @property
    def url(self) -> str:
        """The api_base to give a planner (OpenAI style, ending in /v1)."""
        return f"http://127.0.0.1:{self._server.server_address[1]}/v1"

    @property
    def count(self) -> int:
        with self._lock:
            return len(self.requests)

    def script(self, *answers: Answer) -> Self:
        with self._lock:
            self._script.extend(answers)
        return self

    def start(self) -> Self:
        self._thread.start()
        return self

    def stop(self) -> None:
        """Die as a killed process does: stop listening and drop every open connection."""
        self._stopping.set()  # wakes handlers sleeping in a slow answer
        self._server.shutdown()
        self._server.server_close()
        with self._lock:
            for connection in self._connections:
                with contextlib.suppress(OSError):
                    connection.shutdown(socket.SHUT_RDWR)

    def __enter__(self) -> Self:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def _refusal(self, body: dict, authorization: str | None) -> Answer | None:
        """What a real server says before it runs the model: bad key, unknown model, too long a prompt."""
        if self.api_key and authorization != f"Bearer {self.api_key}":
            return http_error(401, "Incorrect API key provided.")
        if self.models is not None and body.get("model") not in self.models:
            return http_error(404, f"The model `{body.get('model')}` does not exist or you do not have "
                                   "access to it.")
        return self.gate(body) if self.gate else None

    def _next_answer(self, body: dict, path: str, authorization: str | None = None) -> Answer:
        refusal = self._refusal(body, authorization)
        with self._lock:
            index = len(self.requests)
            self.in_progress += 1
            self.peak = max(self.peak, self.in_progress)
            self.requests.append(body)
            self.paths.append(path)
            scripted = None if refusal or not self._script else self._script.popleft()
        default = self.default(body, index) if callable(self.default) else self.default
        answer = refusal or scripted or default
        with self._lock:
            self.served[answer.kind] += 1
        return answer

    def _done(self, answered: bool) -> None:
        with self._lock:
            self.in_progress -= 1
            self.answered += answered

    def stats(self) -> dict:
        with self._lock:
            return {"requests": len(self.requests), "served": dict(self.served)}


class _Handler(BaseHTTPRequestHandler):
    """One connection to `fake` (the FakeOpenAI whose server made it)."""

    fake: FakeOpenAI
    protocol_version = "HTTP/1.1"  # keep-alive, as real providers do

    def setup(self) -> None:
        super().setup()
        with self.fake._lock:
            self.fake._connections.add(self.connection)

    def log_message(self, *args: object) -> None:  # keep test output quiet
        pass

    def do_GET(self) -> None:
        if self.path == "/stats":  # for a server in another process (the load benchmark)
            self._send(200, self.fake.stats())
        elif self.path.split("?")[0] in ("/v1/models", "/models") and self.fake.listing is not None:
            self._send(200, self.fake.listing)
        else:
            self._send(404, {"error": {"message": f"no route {self.path}"}})

    def do_POST(self) -> None:
        raw = self.rfile.read(int(self.headers.get("Content-Length", 0)))
        if self.path.split("?")[0] not in CHAT_PATHS:
            self._send(404, {"error": {"message": f"no route {self.path}"}})
            return
        try:
            body = json.loads(raw)
        except json.JSONDecodeError:
            self._send(400, {"error": {"message": "request body is not JSON"}})
            return
        answer = self.fake._next_answer(body, self.path, self.headers.get("Authorization"))
        delay_s = answer.delay_s + (0.0 if body.get("stream") else generation_s(answer))
        if delay_s and self.fake._stopping.wait(delay_s):
            sent = False  # the server is shutting down
        elif answer.status != 200:
            sent = self._send(answer.status, _error_body(answer.status, answer.message),
                              answer.headers)
        elif body.get("stream"):
            sent = send_stream(self, answer, body.get("model", ""), self.fake)
        else:
            sent = self._send(200, _completion_body(answer, body), answer.headers)
        self.fake._done(sent)

    def _send(self, status: int, payload: dict, headers: dict | None = None) -> bool:
        data = json.dumps(payload).encode()
        try:
            self.send_response(status)
            self.send_header("Content-Type", "application/json")
            self.send_header("Content-Length", str(len(data)))
            for key, value in (headers or {}).items():
                self.send_header(key, value)
            self.end_headers()
            self.wfile.write(data)
        except (BrokenPipeError, ConnectionResetError):
            return False  # the client gave up (a timeout test); nothing to tell it
        return True


def main() -> None:
    """Serve from a separate process (so the client under load does not share our GIL): prints
    {"url": ...} on the first stdout line, serves until stdin closes. GET /stats gives the counts."""
    parser = argparse.ArgumentParser(description="scripted OpenAI-compatible server on 127.0.0.1")
    parser.add_argument("--delay", type=float, default=0.0)
    parser.add_argument("--bad-rate", type=float, default=0.0)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--mix", nargs="+", default=["malformed", "http_500"], choices=sorted(FAULTS))
    parser.add_argument("--slow", type=float, default=0.0, help="extra delay of a bad answer, s")
    parser.add_argument("--api-key", default=None)
    parser.add_argument("--models", nargs="*", default=None)
    parser.add_argument("--context-window", type=int, default=None)
    parser.add_argument("--reply", default=None,
                        help="answer with this text ({n}: the request's number), paced")
    parser.add_argument("--first-token-s", type=float, default=0.0)
    parser.add_argument("--tokens-per-s", type=float, default=0.0)
    args = parser.parse_args()
    default = (faulty(args.delay, args.bad_rate, args.seed, tuple(args.mix), args.slow) if args.reply is None
               else lambda body, n: streamed(args.reply.replace("{n}", str(n)), args.first_token_s,
                                             args.tokens_per_s))
    with FakeOpenAI(default, args.api_key, args.models and tuple(args.models), args.context_window) as server:
        print(json.dumps({"url": server.url}), flush=True)
        sys.stdin.read()


if __name__ == "__main__":
    main()
