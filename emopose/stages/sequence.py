"""Sequence: scheduled gestures -> commands queued in the sequencer, released against the speech start.

The speech start is planned here (now, plus the audio device's expected latency, plus the timeline's
pre-roll) and the dispatch stage
starts the audio (moving the gestures if it starts at another time); gestures are released at speech
start + their scheduled release. Trajectory
construction (Eq. smoothstep) happens inside the sequencer when a command is dequeued, so it starts
from the pose actually published at that moment. This stage measures the paper's "command submission"
latency: the non-blocking hand-off into the sequencer's queue. A timeline schedule becomes timed
commands (keyframe times on the stream clock) in the order they start; gestures it dropped are reported
to the sequencer as "dropped" events and never queued.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

from emopose.clock import Clock
from emopose.execution.gesture_command import GestureCommand
from emopose.execution.sequencer import Sequencer
from emopose.speech.player import Player
from emopose.turn.model import ModulatedGesture, Release, Submission, Turn


@dataclass
class SequenceStage:
    """Stage: speech + schedule -> submitted. `interrupt=True` replaces whatever is running (a new
    utterance) instead of queueing behind it, unless the turn performs nothing (Turn.performs_nothing)."""

    sequencer: Sequencer = field(repr=False)
    clock: Clock = field(repr=False)
    player: Player = field(repr=False)  # read for its expected latency only; dispatch plays the audio
    interrupt: bool = False
    name = "sequence"
    reads = ("speech", "schedule")
    writes = ("submitted",)

    def queueing(self) -> SequenceStage:
        """A copy that queues behind the gestures already handed over instead of interrupting them."""
        return replace(self, interrupt=False)

    def __call__(self, turn: Turn) -> Submission:
        schedule = turn.schedule
        now = self.clock.now()
        speech_start = now + self.player.expected_latency_s(turn.speech, self.clock) + schedule.preroll_s
        planned = [self._command(k, g, r, speech_start)
                   for k, (g, r) in enumerate(zip(schedule.gestures, schedule.releases))]
        for command, release in zip(planned, schedule.releases):
            if release.dropped:
                self.sequencer.drop(command, release.dropped, now)
        commands = sorted((c for c, r in zip(planned, schedule.releases) if not r.dropped),
                          key=lambda c: c.release_at)
        timings = []
        if self.interrupt and not turn.performs_nothing():
            started = time.perf_counter()
            self.sequencer.interrupt(commands, now=self.clock.now())
            timings.append(time.perf_counter() - started)
        else:
            for command in commands:
                started = time.perf_counter()
                self.sequencer.submit(command)
                timings.append(time.perf_counter() - started)
        return Submission(tuple(commands), speech_start, tuple(timings), play_at=now + schedule.preroll_s)

    @staticmethod
    def _command(k: int, gesture: ModulatedGesture, release: Release, speech_start: float) -> GestureCommand:
        common = dict(name=gesture.name, duration=gesture.duration,
                      release_at=speech_start + release.release_s, label=gesture.resolved.record.cls,
                      record=k)
        timing = release.timing
        if timing is None:
            entry = gesture.resolved.entry
            authored = None if entry.times is None else tuple(
                t * gesture.duration / entry.times[-1] for t in entry.times)
            return GestureCommand(keyframes=gesture.keyframes, stroke=entry.stroke_span,
                                  authored_times=authored, **common)
        offsets = tuple(t - timing.times[0] for t in timing.times)
        return GestureCommand(keyframes=timing.keyframes, stroke=timing.stroke, offsets=offsets,
                              blend_in=timing.blend_in, cut=timing.cut, **common)
