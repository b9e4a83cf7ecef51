"""Dispatch: start the reply's audio and run the submitted commands through the 50 Hz control loop.

The audio starts when the sequence stage says (after the timeline's pre-roll, if any).
The sequence stage released the gestures against the planned speech start; when the audio actually
starts at another time (a device's launch and output latency), the queued gestures are moved by the
difference, so they keep their place on the words as heard. A turn that performs nothing (no words,
every gesture dropped) neither plays nor waits: a reply already playing goes on.

When the loop already runs on its own thread (web UI, tour, G1), dispatch waits on it if asked to;
otherwise it drives the loop on this thread until the sequencer settles (offline rendering with a
fake clock, or real time with the monotonic clock).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

from emopose.execution.control_loop import ControlLoop
from emopose.execution.sequencer import State
from emopose.speech.player import Player
from emopose.turn.model import DispatchReport, Turn

UNTIL = ("settle", "rest", "none")


@dataclass
class Dispatch:
    """Stage: speech + submitted -> dispatched. `settle` waits until the last gesture ends (HOLDING),
    `rest` also for the recovery to neutral, `none` returns at once."""

    loop: ControlLoop = field(repr=False)
    player: Player = field(repr=False)
    timeout_s: float = 60.0
    until: str = "rest"
    follow: bool = False  # a streamed reply's sentences: the audio follows the clip playing (no cut)
    name = "dispatch"
    reads = ("speech", "submitted")
    writes = ("dispatched",)

    def __post_init__(self) -> None:
        if self.until not in UNTIL:
            raise ValueError(f"pipeline.dispatch.until must be one of {UNTIL}, got {self.until!r}")

    def waiting_until(self, until: str) -> Dispatch:
        """A copy that waits `until` (one of UNTIL) after dispatching."""
        return replace(self, until=until)

    def streamed(self, follow: bool) -> Dispatch:
        """A copy for one sentence of a streamed reply: it returns at once (the runner waits after the
        last sentence); with `follow` its audio follows the clip playing instead of cutting it."""
        return replace(self, until="none", follow=follow)

    def __call__(self, turn: Turn) -> DispatchReport:
        sequencer = self.loop.sequencer
        first_event, ticks = sequencer.events.total, self.loop.stats.ticks
        if turn.performs_nothing():  # no words, no gesture: the reply playing, if any, goes on
            events = tuple(sequencer.events.since(first_event))
            return DispatchReport(True, events, 0, turn.submitted.speech_start)
        clock, play_at = self.loop.clock, turn.submitted.play_at
        if clock.now() < play_at:  # the timeline's pre-roll: the first gesture prepares before the words
            self.loop.wait_until(lambda: clock.now() >= play_at - 1e-9, play_at - clock.now() + 1.0)
        speech_start = (self.player.play(turn.speech, clock, follow=True) if self.follow
                        else self.player.play(turn.speech, clock))
        late = speech_start - turn.submitted.speech_start
        if late:
            sequencer.retime({c.id for c in turn.submitted.commands}, late)
        done = self.wait()
        return DispatchReport(done, tuple(sequencer.events.since(first_event)), self.loop.stats.ticks - ticks,
                              speech_start)

    def wait(self) -> bool:
        """Wait as `until` says (a streamed reply waits once, after its last sentence); False on timeout."""
        sequencer = self.loop.sequencer
        if self.until == "none":
            return True
        if self.until == "settle":
            return self.loop.wait_until(sequencer.settled, self.timeout_s)
        return self.loop.wait_until(lambda: sequencer.settled() and sequencer.state == State.IDLE,
                                    self.timeout_s)
