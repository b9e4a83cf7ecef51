"""A streamed chat answer: the text deltas as the model writes them, with the client's timeouts and retries.

Opening the stream is one request (LLMClient.open_stream): transient failures are retried before any
text has come, unmendable ones fail at once with their cause. Once text has come a failure is final,
since what was said is said: LLMCallError naming what broke. A stream that ends without a
finish_reason (the server died between two chunks) is such a failure too, and so is a stream still
running at planner.client.timeout_s (a watchdog closes it: a hard deadline on the whole answer, as
for an unstreamed call). cancel(), from any thread, ends the iteration and closes the HTTP stream, so
the server sees the connection go. Control characters are dropped from every piece.
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections.abc import Iterator

from emopose.llm.client import LLMClient
from emopose.llm.deadline import clean_text
from emopose.llm.errors import LLMCallError, cause


class TextStream:
    """Iterate once for the answer's text pieces; first_token_s, attempts and finish_reason fill in."""

    def __init__(self, client: LLMClient, messages: list[dict]) -> None:
        self.client, self.messages = client, messages
        self.first_token_s: float | None = None  # from the request
        self.finish_reason: str | None = None
        self.attempts = 0
        self.expired = False  # the watchdog closed it at timeout_s
        self._cancelled = threading.Event()
        self._response: object | None = None
        self._lock = threading.Lock()

    @property
    def cancelled(self) -> bool:
        return self._cancelled.is_set()

    def cancel(self) -> None:
        self._cancelled.set()
        with self._lock:
            response, self._response = self._response, None
        _close(response)  # unblocks a read waiting on a silent server

    def _expire(self) -> None:
        self.expired = True
        self.cancel()

    def __iter__(self) -> Iterator[str]:
        started = time.perf_counter()
        response, self.attempts = self.client.open_stream(self.messages)
        with self._lock:
            self._response = None if self.cancelled else response
        left_s = max(0.0, started + self.client.timeout_s - time.perf_counter())
        watchdog = threading.Timer(left_s, self._expire)
        watchdog.daemon = True
        watchdog.start()
        try:
            yield from self._texts(response, started)
        finally:
            watchdog.cancel()
            _close(response)
            self.client.counters.latency(time.perf_counter() - started)

    def _texts(self, response, started: float) -> Iterator[str]:
        received = 0
        try:
            for chunk in response:
                if self.cancelled:
                    break
                choice = chunk.choices[0] if chunk.choices else None
                if choice is None:
                    continue
                self.finish_reason = choice.finish_reason or self.finish_reason
                text = clean_text(choice.delta.content or "") if choice.delta is not None else ""
                if text:
                    if self.first_token_s is None:
                        self.first_token_s = time.perf_counter() - started
                    received += len(text)
                    yield text
        except Exception as exc:  # noqa: BLE001 - litellm and httpx raise many types for a broken stream
            if not self.cancelled:  # else our own close() broke the read
                raise LLMCallError(f"the answer stream broke after {received} characters: "
                                   f"{type(exc).__name__}: {str(exc)[:200]}", time.perf_counter() - started,
                                   cause(exc, self.client.model, self.client.api_base)) from exc
        if self.expired:
            raise LLMCallError(f"the answer stream was still running at planner.client.timeout_s = "
                               f"{self.client.timeout_s:g} s after {received} characters; closed",
                               time.perf_counter() - started)
        if self.finish_reason is None and not self.cancelled:
            raise LLMCallError(f"the answer stream ended after {received} characters without a finish_reason "
                               "(the server stopped mid-answer)", time.perf_counter() - started)


def _close(response: object | None) -> None:
    close = getattr(response, "close", None)
    if callable(close):
        with contextlib.suppress(Exception):  # best effort: the stream may already be gone
            close()
