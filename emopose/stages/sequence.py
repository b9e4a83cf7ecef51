"""Sequence: scheduled gestures -> commands queued in the sequencer, released against the speech start.

The speech start is planned here (now, plus the audio device's expected latency) and the dispatch stage
starts the audio (moving the gestures if it starts at another time); gestures are released at speech
start + their scheduled release. Trajectory
construction (Eq. smoothstep) happens inside the sequencer when a command is dequeued, so it starts
from the pose actually published at that moment. This stage measures the paper's "command submission"
latency: the non-blocking hand-off into the sequencer's queue.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

from emopose.clock import Clock
from emopose.sequencer import GestureCommand, Sequencer
from emopose.speech.player import Player
from emopose.turn import Submission, Turn


@dataclass
class SequenceStage:
    """Stage: speech + schedule -> submitted. `interrupt=True` replaces whatever is running (a new
    utterance) instead of queueing behind it."""

    sequencer: Sequencer = field(repr=False)
    clock: Clock = field(repr=False)
    player: Player = field(repr=False)  # read for its expected latency only; dispatch plays the audio
    interrupt: bool = False
    name = "sequence"
    reads = ("speech", "schedule")
    writes = ("submitted",)

    def __call__(self, turn: Turn) -> Submission:
        schedule = turn.schedule
        speech_start = self.clock.now() + self.player.expected_latency_s(turn.speech, self.clock)
        commands = [
            GestureCommand(name=g.name, keyframes=g.keyframes, duration=g.duration,
                           release_at=speech_start + release.release_s, label=g.resolved.record.cls)
            for g, release in zip(schedule.gestures, schedule.releases)
        ]
        timings = []
        if self.interrupt:
            started = time.perf_counter()
            self.sequencer.interrupt(commands, now=self.clock.now())
            timings.append(time.perf_counter() - started)
        else:
            for command in commands:
                started = time.perf_counter()
                self.sequencer.submit(command)
                timings.append(time.perf_counter() - started)
        return Submission(tuple(commands), speech_start, tuple(timings))
