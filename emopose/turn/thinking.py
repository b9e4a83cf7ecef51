"""Latency masking: a "thinking" library motion plays while the planner works (beyond the paper).

The turn runner wraps every planner call in `around_planning()`. The motion is queued `repeats` times,
released at once, so a slow model keeps the robot visibly thinking: on entry if the sequencer is settled,
else (a previous reply's gestures are never cut short for it) the moment it settles while the plan is
still pending (`Planning.poll`, every control period on a watcher thread), so a plan that outlasts the
previous gesture never leaves the robot standing still. A plan that arrives first queues nothing. When
the plan arrives, whatever is left of the motion is interrupted through the sequencer's normal
interruption path: pending repeats are cleared and a blend starts from the latest published pose
toward neutral. Blending is a recovery state
in which released commands start at once, so the plan's first gesture still starts at its scheduled
release, again from the latest published pose: the stream stays continuous and within the speed
bound, because every transition is built by the same speed-checked TrajectoryBuilder.
With a loop driven on the caller's thread (offline, FakeClock) no time passes while planning, so the
motion never starts and the interruption is a no-op blend at the rest pose.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field

from emopose import CONTROL_DT
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
    def around_planning(self) -> Iterator[Planning]:
        planning = Planning(self)
        if not planning.poll():  # the sequencer is busy: start when it settles, if the plan is still pending
            planning.watcher = threading.Thread(target=planning.watch, name="emopose-thinking", daemon=True)
            planning.watcher.start()
        try:
            yield planning
        finally:
            planning.end()

    def start(self) -> set[int]:
        """Queue the thinking motion unless the sequencer is busy; returns the queued command ids."""
        sequencer = self.sequencer
        entry = self.library.get(self.motion)  # the live library: the motion may have been edited
        if entry is None or not sequencer.settled():
            return set()
        now = self.clock.now()
        commands = [GestureCommand(name=entry.name, keyframes=entry.q, duration=entry.default_duration,
                                   release_at=now, label=THINKING_LABEL, authored_times=entry.times)
                    for _ in range(self.repeats)]
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


class Planning:
    """One planner call's thinking motion: queued once, and only while the plan is pending."""

    def __init__(self, gesture: ThinkingGesture) -> None:
        self.gesture = gesture
        self.ids: set[int] = set()  # the queued thinking commands (empty: not queued yet, or never)
        self.watcher: threading.Thread | None = None
        self._arrived = threading.Event()
        self._lock = threading.Lock()  # a poll and the plan's arrival never interleave

    def poll(self) -> bool:
        """Queue the motion if the sequencer is settled and the plan pending; True: nothing to wait for."""
        with self._lock:
            if not self.ids and not self._arrived.is_set():
                self.ids = self.gesture.start()
            return bool(self.ids) or self._arrived.is_set()

    def watch(self) -> None:
        """Poll every control period until the motion is queued or the plan arrives."""
        while not self.poll():
            self._arrived.wait(CONTROL_DT)

    def end(self) -> None:
        """The plan arrived (or was cancelled): nothing is queued from now on; what was queued stops."""
        with self._lock:
            self._arrived.set()
            ids = self.ids
        self.gesture.stop(ids)
