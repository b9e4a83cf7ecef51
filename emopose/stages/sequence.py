"""Sequence: scheduled gestures -> commands queued in the sequencer, released against speech start.

Trajectory construction (Eq. smoothstep) happens inside the sequencer when a command is dequeued, so
it starts from the pose actually published at that moment. This stage measures the paper's "command
submission" latency: the non-blocking hand-off into the sequencer's queue.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from emopose.sequencer import GestureCommand


@dataclass(frozen=True)
class Submission:
    commands: tuple[GestureCommand, ...]
    speech_start: float
    submission_s: tuple[float, ...]


@dataclass
class SequenceStage:
    """Stage: schedule -> submitted. `interrupt=True` replaces whatever is running (a new utterance)."""

    interrupt: bool = False
    name = "sequence"
    reads = ("schedule",)
    writes = "submitted"

    def __call__(self, turn, ctx) -> Submission:
        schedule = turn.schedule
        speech_start = ctx.start_speech(schedule.speech)
        commands = [
            GestureCommand(name=g.name, keyframes=g.keyframes, duration=g.duration,
                           release_at=speech_start + release.release_s, label=g.resolved.record.cls)
            for g, release in zip(schedule.gestures, schedule.releases)
        ]
        timings = []
        if self.interrupt:
            started = time.perf_counter()
            ctx.sequencer.interrupt(commands, now=ctx.clock.now())
            timings.append(time.perf_counter() - started)
        else:
            for command in commands:
                started = time.perf_counter()
                ctx.sequencer.submit(command)
                timings.append(time.perf_counter() - started)
        return Submission(tuple(commands), speech_start, tuple(timings))
