"""What every planner offers: a request in, raw contract text out (the parse stage makes it a Plan).

Planners own the protocol with their model (a chat prompt, a label-only question, a classifier), but
always answer in the contract's JSON: {"reply": str, "gestures": [{"class", "variant", "intensity",
"trigger", "confidence"}, ...]}. That keeps one parser, one validation edge, and one place that can fail.
"""

from __future__ import annotations

import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Protocol, runtime_checkable


@dataclass(frozen=True)
class PlanRequest:
    """An utterance to plan gestures for, with optional dialogue history and an optional image.

    history: [{"role": "user" | "assistant", "content": str}, ...], oldest first.
    image: a path to an image file, raw PNG/JPEG bytes, or None.
    """

    utterance: str
    history: tuple[dict, ...] = ()
    image: str | bytes | None = None


@dataclass(frozen=True)
class PlannerOutput:
    """The planner's raw answer in contract JSON, its latency, and whether it is a fallback answer.

    fallback: the model gave no answer (the call failed for good) and `raw` holds the keyword rules'.
    meta["attempts"]: requests it took (> 1: transient errors were retried); 0 for a cached answer.
    line: the words the robot must say whatever the answer (narrate mode); parse keeps them when the
    answer is not a usable plan, so chatter from the model is never spoken in place of the line.
    """

    raw: str
    latency_s: float = 0.0
    fallback: bool = False
    error: str | None = None
    meta: dict = field(default_factory=dict)
    line: str | None = None


class PlannerFailure(RuntimeError):
    """The planner's answers cannot stand as its result: it cannot answer at all (endpoint gone, key
    revoked), or a suite run fell back on too many items. The CLI exits 2 with this one-line cause
    instead of reporting keyword fallbacks as the planner's score."""


class PlannerMode(StrEnum):
    """Who writes the words the robot says: the planner (respond) or the caller (narrate: the
    utterance)."""

    RESPOND = "respond"
    NARRATE = "narrate"

    @classmethod
    def parse(cls, value: str) -> PlannerMode:
        """The mode planner.mode names; a ValueError lists the choices."""
        try:
            return cls(value)
        except ValueError:
            raise ValueError(f"planner.mode = {value!r}; choose one of {[m.value for m in cls]}") from None


@runtime_checkable
class Planner(Protocol):
    """name: shown in results; sampled: answers vary between passes (suites then run 5 passes)."""

    name: str
    sampled: bool

    def plan(self, request: PlanRequest) -> PlannerOutput: ...


@runtime_checkable
class CheckedPlanner(Protocol):
    """A planner that calls a service checks it (key, model string, endpoint) before any run starts;
    `check()` raises ValueError naming what is missing."""

    def check(self) -> None: ...


@runtime_checkable
class BatchPlanner(Protocol):
    """A planner that plans many requests concurrently (LLM calls)."""

    def plan_many(self, requests: Sequence[PlanRequest]) -> list[PlannerOutput]: ...


@runtime_checkable
class ModalPlanner(Protocol):
    """A planner whose mode is configurable (PlannerMode)."""

    mode: PlannerMode


def plan_all(planner: Planner, requests: Sequence[PlanRequest]) -> list[PlannerOutput]:
    """Plan many requests: concurrently where the planner can, one by one otherwise."""
    if isinstance(planner, BatchPlanner):
        return list(planner.plan_many(requests))
    return [planner.plan(r) for r in requests]


@dataclass
class _Stopwatch:
    start: float
    elapsed: float = 0.0


@contextmanager
def timed() -> Iterator[_Stopwatch]:
    watch = _Stopwatch(time.perf_counter())
    try:
        yield watch
    finally:
        watch.elapsed = time.perf_counter() - watch.start
