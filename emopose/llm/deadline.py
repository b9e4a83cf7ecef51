"""A hard deadline on one model call, and the text cleaning every reply gets.

litellm hands `timeout` to httpx as a per-read timeout: a server that trickles its body a byte at a
time (or keeps a stream alive) never trips it, so a 2 s setting could return a 5 s answer. Here the
whole call (connect, prompt evaluation, body) must finish by `timeout_s`: the async call is cancelled
(httpx closes the connection), the sync call is left to its daemon thread and its answer dropped.
"""

from __future__ import annotations

import asyncio
import re
from collections.abc import Awaitable, Callable
from typing import TypeVar

from emopose.background_call import BackgroundCall

T = TypeVar("T")

# C0 and C1 control characters except tab and newline, and terminal escape sequences: a model's colour
# codes, bells and NULs must never reach speech synthesis, the web page or the recording.
_CONTROL = re.compile(r"\x1b\[[0-?]*[ -/]*[@-~]|[\x00-\x08\x0b-\x1f\x7f-\x9f]")  # ANSI escapes whole


class CallTimeout(TimeoutError):
    """The call passed planner.client.timeout_s (transient: retried like any timeout)."""


def clean_text(text: str) -> str:
    """The reply without control characters (a carriage return becomes a space)."""
    return _CONTROL.sub("", text.replace("\r", " "))


def _late(timeout_s: float) -> CallTimeout:
    return CallTimeout(f"no complete answer within planner.client.timeout_s = {timeout_s:g} s")


def call_within(call: Callable[[], T], timeout_s: float) -> T:
    """call() in a daemon thread; its result, or CallTimeout once timeout_s has passed."""
    background = BackgroundCall(call, "llm-call")
    if not background.done.wait(timeout_s):
        raise _late(timeout_s)
    return background.result()


async def await_within(call: Awaitable[T], timeout_s: float) -> T:
    """The awaitable's result, or CallTimeout (the call is cancelled) once timeout_s has passed."""
    try:
        async with asyncio.timeout(timeout_s):  # in this task: litellm keeps the error's cause chain
            return await call
    except TimeoutError:
        raise _late(timeout_s) from None
