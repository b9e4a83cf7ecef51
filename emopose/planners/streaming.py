"""Streamed planning: a reply that arrives sentence by sentence, each sentence already planned.

A planner that can stream (planner=annotate with planner.stream=true) returns SentencePlans: one
PlannerOutput per sentence, in order, as each completes, whose raw answer is that sentence with its
gestures. The turn runner performs each while the model keeps writing (emopose/stream_runner.py).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

from emopose.planners.base import PlannerOutput, PlanRequest


@dataclass
class SentencePlans:
    """Iterate once for the sentences' outputs; cancel() (from any thread) ends the stream and closes it."""

    outputs: Iterator[PlannerOutput]
    cancel: Callable[[], None]

    def __iter__(self) -> Iterator[PlannerOutput]:
        return self.outputs


@runtime_checkable
class StreamingPlanner(Protocol):
    streams: bool            # configured to stream (the runner plans whole replies otherwise)
    stream_preroll_s: float  # the most the first sentence's speech waits for its first gesture

    def stream(self, request: PlanRequest) -> SentencePlans: ...
