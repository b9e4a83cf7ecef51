"""Latency masking: a "thinking" library motion plays while the planner works (beyond the paper).

The turn runner wraps every planner call in `around_planning()`. On entry, if the sequencer is
settled (a previous reply's gestures are never cut short for it), the motion is queued `repeats` times,
released at once, so a slow model keeps the robot visibly thinking. When the plan arrives, whatever is
left of it is interrupted through the sequencer's normal interruption path: pending repeats are
cleared and a blend starts from the latest published pose toward neutral. Blending is a recovery state
in which released commands start at once, so the plan's first gesture still starts at its scheduled
release, again from the latest published pose: the stream stays continuous and within the speed
bound, because every transition is built by the same speed-checked TrajectoryBuilder.
With a loop driven on the caller's thread (offline, FakeClock) no time passes while planning, so the
motion never starts and the interruption is a no-op blend at the rest pose.
"""

from __future__ import annotations

import logging
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field

from emopose.clock import Clock
from emopose.execution.gesture_command import GestureCommand, State
from emopose.execution.sequencer import Sequencer
from emopose.library import MotionLibrary

log = logging.getLogger(__name__)

THINKING_LABEL = "thinking"


@dataclass
class ThinkingGesture:
    library: MotionLibrary = field(repr=False)
    sequencer: Sequencer = field(repr=False)
    clock: Clock = field(repr=False)
    motion: str = "chin_stroke"
    repeats: int = 3

    def __post_init__(self) -> None:
        if self.repeats < 1:
            raise ValueError(f"thinking.repeats must be >= 1, got {self.repeats}")
        if self.library.get(self.motion) is None:
            doubting = [e.name for e in self.library.by_class("doubting")]
            raise ValueError(f"thinking.motion {self.motion!r} is not in the motion library; "
                             f"pick a loaded motion, e.g. one of {doubting or self.library.names[:8]}")

    @contextmanager
    def around_planning(self) -> Iterator[None]:
        ids = self.start()
        try:
            yield
        finally:
            self.stop(ids)

    def start(self) -> set[int]:
        """Queue the thinking motion unless the sequencer is busy; returns the queued command ids."""
        sequencer = self.sequencer
        entry = self.library.get(self.motion)  # the live library: the motion may have been edited
        if entry is None or not sequencer.settled():
            return set()
        now = self.clock.now()
        commands = [GestureCommand(name=entry.name, keyframes=entry.q, duration=entry.default_duration,
                                   release_at=now, label=THINKING_LABEL) for _ in range(self.repeats)]
        for command in commands:
            sequencer.submit(command)
        return {c.id for c in commands}

    def stop(self, ids: set[int]) -> None:
        """The plan arrived: interrupt what is left of the thinking motion (nothing if it already ended)."""
        sequencer = self.sequencer
        if not ids or sequencer.settled():
            return
        active = sequencer.active
        if (active is not None and active.id not in ids) or any(c.id not in ids for c in sequencer.pending):
            return  # someone else's commands are running or queued; leave them to the sequencer
        running = active is not None or sequencer.state == State.BLENDING
        log.info("plan arrived: %s the thinking motion %s", "interrupting" if running else "dropping",
                 self.motion)
        sequencer.interrupt([], now=self.clock.now())
