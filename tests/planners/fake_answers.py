"""Scripted answers for the fake OpenAI server (fake_openai.py): good, bad, failing and slow replies.

Each constructor returns one Answer; `kind` is how the server counts it (GET /stats, FakeOpenAI.served),
so a benchmark can compare what the server sent with what the planner counted. UNUSABLE names the kinds
whose content no parser can turn into a usable model record (the planner must count each as a fallback).
"""

from __future__ import annotations

import json
import random
import threading
from collections.abc import Callable
from dataclasses import dataclass, field

PLAN = {
    "reply": "Welcome! The screen is over there.",
    "gestures": [
        {"class": "welcoming", "variant": "welcoming_a", "intensity": 3, "trigger": "Welcome",
         "confidence": 0.9},
        {"class": "pointing", "variant": "pointing_b", "intensity": 4, "trigger": "over there",
         "confidence": 0.8},
    ],
}
PLAN_JSON = json.dumps(PLAN)
UNUSABLE = frozenset({"malformed", "truncated", "plain", "unknown_class", "empty"})


@dataclass
class Answer:
    """One scripted reply: a chat message `content`, or an HTTP error `status` with an error body."""

    content: str | None = ""
    status: int = 200
    delay_s: float = 0.0
    finish_reason: str = "stop"
    headers: dict[str, str] = field(default_factory=dict)
    kind: str = "custom"  # how GET /stats counts it
    message: str | None = None  # the error message of a non-200 answer


def ok(content: str = PLAN_JSON, delay_s: float = 0.0) -> Answer:
    return Answer(content=content, delay_s=delay_s, kind="ok")


def malformed() -> Answer:
    return Answer(content='{"reply": "Sure", "gestures": [{"class": "agreeing", intensity: high}',
                  kind="malformed")


def empty() -> Answer:
    return Answer(content="", kind="empty")


def truncated(plan_json: str = PLAN_JSON) -> Answer:
    return Answer(content=plan_json[: len(plan_json) // 2], finish_reason="length", kind="truncated")


def oversized(chars: int = 300_000) -> Answer:
    return Answer(content=PLAN_JSON + " " * chars, kind="oversized")


def fenced(plan_json: str = PLAN_JSON) -> Answer:
    """Usable: the plan inside a markdown fence."""
    return Answer(content=f"Here you go:\n```json\n{plan_json}\n```", kind="fenced")


def plain() -> Answer:
    """Unusable: chatter instead of a plan."""
    return Answer(content="Sure! I would wave and then point at the screen.", kind="plain")


def _first_record(plan_json: str, **changes: object) -> str:
    plan = json.loads(plan_json)
    plan["gestures"][0].update(changes)
    return json.dumps(plan)


def unknown_class(plan_json: str = PLAN_JSON) -> Answer:
    """Unusable: the first record's class is not one of the eight."""
    return Answer(content=_first_record(plan_json, **{"class": "waving"}), kind="unknown_class")


def loud(plan_json: str = PLAN_JSON) -> Answer:
    """Usable: intensity 9 is clamped to 5."""
    return Answer(content=_first_record(plan_json, intensity=9), kind="loud")


def http_error(status: int = 500, message: str | None = None) -> Answer:
    return Answer(content=None, status=status, kind=f"http_{status}", message=message)


def rate_limited(retry_after_s: float = 0.0) -> Answer:
    return Answer(content=None, status=429, headers={"retry-after": str(retry_after_s)},
                  kind="rate_limited")


def slow(delay_s: float, content: str = PLAN_JSON) -> Answer:
    return Answer(content=content, delay_s=delay_s, kind="slow")


# The fault mix, in equal shares of the bad rate: what a small or flaky model really sends.
# Each makes its fault from the good answer's plan JSON (so a usable fault still carries the right class).
FAULTS: dict[str, Callable[[str], Answer]] = {
    "malformed": lambda good: malformed(), "truncated": truncated, "plain": lambda good: plain(),
    "unknown_class": unknown_class, "fenced": fenced, "loud": loud, "http_500": lambda good: http_error(500),
}


def faulty(delay_s: float, bad_rate: float, seed: int = 0, mix: tuple[str, ...] = ("malformed", "http_500"),
           slow_s: float = 0.0,
           good: Callable[[dict], str] = lambda body: PLAN_JSON) -> Callable[[dict, int], Answer]:
    """A default for load tests: every answer after delay_s; bad_rate of them drawn evenly from `mix`
    (names in FAULTS), per request (so a retried 500 draws again), from a seeded generator. A bad answer
    also waits `slow_s` more (the issue's 3 s delays). `good(body)` is the right plan for a request; a
    planner's probe (max_tokens 1) always gets it, so the faults are the items'."""
    rng, lock = random.Random(seed), threading.Lock()
    unknown = sorted(set(mix) - set(FAULTS))
    if unknown:
        raise ValueError(f"unknown fault kinds {unknown}; choose from {sorted(FAULTS)}")

    def answer(body: dict, index: int) -> Answer:
        if body.get("max_tokens") == 1:
            return ok(good(body), delay_s)
        with lock:
            draw, pick = rng.random(), rng.randrange(len(mix))
        bad = draw < bad_rate
        chosen = FAULTS[mix[pick]](good(body)) if bad else ok(good(body))
        chosen.delay_s = delay_s + (slow_s if bad else 0.0)
        return chosen

    return answer


def prompt_tokens(body: dict) -> int:
    """A server-side token estimate (4 characters a token), as a context-window check would make."""
    return len(json.dumps(body.get("messages", []))) // 4


def context_overflow(window: int) -> Callable[[dict], Answer | None]:
    """A gate: a request whose prompt + max_tokens exceeds `window` gets OpenAI's context-length 400."""

    def gate(body: dict) -> Answer | None:
        wanted = prompt_tokens(body) + int(body.get("max_tokens") or 0)
        if wanted <= window:
            return None
        return http_error(400, f"This model's maximum context length is {window} tokens. However, you "
                               f"requested {wanted} tokens. Please reduce the length of the messages.")

    return gate
