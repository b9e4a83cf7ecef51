"""A scripted OpenAI-compatible chat server on 127.0.0.1 for planner tests and the fake benchmark.

Real sockets, real HTTP: the planner under test talks to it through litellm exactly as it would to a
hosted provider (api_base = server.url), so nothing inside litellm is mocked. Answers come from a
FIFO script first, then from `default` (an Answer, or a callable (body, index) -> Answer). Every
request body is recorded for assertions, and two counters stand in for wall-clock bounds: `peak`
(the most requests in progress at once: concurrency) and `answered` (answers sent so far; one still
sitting out its delay is not, so a client that returned before it has timed out).

    with FakeOpenAI() as server:
        server.script(http_error(500), ok(PLAN_JSON))
        ... planner(api_base=server.url) ...
        assert server.count == 2
"""

from __future__ import annotations

import argparse
import json
import random
import sys
import threading
import time
from collections import Counter, deque
from collections.abc import Callable
from dataclasses import dataclass, field
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Self

PLAN_JSON = json.dumps({
    "reply": "Welcome! The screen is over there.",
    "gestures": [
        {"class": "welcoming", "variant": "welcoming_a", "intensity": 3, "trigger": "Welcome",
         "confidence": 0.9},
        {"class": "pointing", "variant": "pointing_b", "intensity": 4, "trigger": "over there",
         "confidence": 0.8},
    ],
})
CHAT_PATHS = ("/v1/chat/completions", "/chat/completions")


@dataclass
class Answer:
    """One scripted reply: a chat message `content`, or an HTTP error `status` with an error body."""

    content: str | None = ""
    status: int = 200
    delay_s: float = 0.0
    finish_reason: str = "stop"
    headers: dict[str, str] = field(default_factory=dict)
    kind: str = "custom"  # how GET /stats counts it


def ok(content: str = PLAN_JSON, delay_s: float = 0.0) -> Answer:
    return Answer(content=content, delay_s=delay_s, kind="ok")


def malformed() -> Answer:
    return Answer(content='{"reply": "Sure", "gestures": [{"class": "agreeing", intensity: high}', kind="malformed")


def empty() -> Answer:
    return Answer(content="", kind="empty")


def truncated() -> Answer:
    return Answer(content=PLAN_JSON[: len(PLAN_JSON) // 2], finish_reason="length", kind="truncated")


def oversized(chars: int = 300_000) -> Answer:
    return Answer(content=PLAN_JSON + " " * chars, kind="oversized")


def http_error(status: int = 500) -> Answer:
    return Answer(content=None, status=status, kind=f"http_{status}")


def rate_limited(retry_after_s: float = 0.0) -> Answer:
    return Answer(content=None, status=429, headers={"retry-after": str(retry_after_s)},
                  kind="rate_limited")


def slow(delay_s: float, content: str = PLAN_JSON) -> Answer:
    return Answer(content=content, delay_s=delay_s, kind="slow")


def faulty(delay_s: float, bad_rate: float, seed: int = 0) -> Callable[[dict, int], Answer]:
    """A default for load tests: every answer after delay_s; bad_rate of them bad, half malformed JSON
    and half HTTP 500, drawn per request (so a retried 500 draws again) from a seeded generator."""
    rng, lock = random.Random(seed), threading.Lock()

    def answer(body: dict, index: int) -> Answer:
        with lock:
            draw = rng.random()
        chosen = http_error(500) if draw < bad_rate / 2 else malformed() if draw < bad_rate else ok()
        chosen.delay_s = delay_s
        return chosen

    return answer


def _completion_body(answer: Answer, model: str) -> dict:
    return {
        "id": "chatcmpl-fake", "object": "chat.completion", "created": int(time.time()), "model": model,
        "choices": [{"index": 0, "finish_reason": answer.finish_reason,
                     "message": {"role": "assistant", "content": answer.content}}],
        "usage": {"prompt_tokens": 10, "completion_tokens": 10, "total_tokens": 20},
    }


def _error_body(status: int) -> dict:
    kind = {429: "rate_limit_exceeded", 401: "invalid_api_key"}.get(status, "server_error")
    return {"error": {"message": f"scripted HTTP {status}", "type": kind, "code": kind}}


class FakeOpenAI:
    """The server; use as a context manager, or start()/stop()."""

    def __init__(self, default: Answer | Callable[[dict, int], Answer] | None = None) -> None:
        self.default = default or ok()
        self.requests: list[dict] = []
        self.paths: list[str] = []
        self.served: Counter[str] = Counter()  # answer kinds sent, e.g. {"ok": 9, "http_500": 1}
        self.in_progress = self.peak = self.answered = 0
        self._script: deque[Answer] = deque()
        self._lock = threading.Lock()
        self._stopping = threading.Event()
        self._server = ThreadingHTTPServer(("127.0.0.1", 0), self._handler_class())
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
        self._stopping.set()  # wakes handlers sleeping in a slow answer
        self._server.shutdown()
        self._server.server_close()

    def __enter__(self) -> Self:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def _next_answer(self, body: dict, path: str) -> Answer:
        with self._lock:
            index = len(self.requests)
            self.in_progress += 1
            self.peak = max(self.peak, self.in_progress)
            self.requests.append(body)
            self.paths.append(path)
            scripted = self._script.popleft() if self._script else None
        answer = scripted or (self.default(body, index) if callable(self.default) else self.default)
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

    def _handler_class(self) -> type[BaseHTTPRequestHandler]:
        server = self

        class Handler(BaseHTTPRequestHandler):
            protocol_version = "HTTP/1.1"  # keep-alive, as real providers do

            def log_message(self, *args: object) -> None:  # keep test output quiet
                pass

            def do_GET(self) -> None:
                if self.path == "/stats":  # for a server in another process (the load benchmark)
                    self._send(200, server.stats())
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
                answer = server._next_answer(body, self.path)
                if answer.delay_s and server._stopping.wait(answer.delay_s):
                    sent = False  # the server is shutting down
                elif answer.status != 200:
                    sent = self._send(answer.status, _error_body(answer.status), answer.headers)
                else:
                    sent = self._send(200, _completion_body(answer, body.get("model", "")), answer.headers)
                server._done(sent)

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

        return Handler


def main() -> None:
    """Serve from a separate process (so the client under load does not share our GIL): prints
    {"url": ...} on the first stdout line, serves until stdin closes. GET /stats gives the counts."""
    parser = argparse.ArgumentParser(description="scripted OpenAI-compatible server on 127.0.0.1")
    parser.add_argument("--delay", type=float, default=0.0)
    parser.add_argument("--bad-rate", type=float, default=0.0)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    with FakeOpenAI(default=faulty(args.delay, args.bad_rate, args.seed)) as server:
        print(json.dumps({"url": server.url}), flush=True)
        sys.stdin.read()


if __name__ == "__main__":
    main()
