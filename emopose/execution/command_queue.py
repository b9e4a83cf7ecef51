"""The sequencer's released-command queue and its event report, thread-safe (the tick: sequencer.py).

Commands wait here, in order, until their release; what happens to each (started, stroke, cut, dropped,
...) is an Event, kept in a bounded log and handed to `on_event` (the session records it).
"""

from __future__ import annotations

import threading
from collections import deque
from collections.abc import Callable
from dataclasses import replace

from emopose.contract import EventKind
from emopose.execution.bounded_log import BoundedLog
from emopose.execution.gesture_command import Event, GestureCommand


class CommandQueue:
    def __init__(self, on_event: Callable[[Event], None] | None, keep_events: int) -> None:
        self.on_event = on_event
        self.events: BoundedLog[Event] = BoundedLog(keep_events)
        self._lock = threading.RLock()
        self._queue: deque[GestureCommand] = deque()

    def submit(self, command: GestureCommand) -> None:
        with self._lock:
            self._queue.append(command)

    def drop(self, command: GestureCommand, reason: str, now: float) -> None:
        """Record a gesture the timeline could not fit (it is never queued)."""
        with self._lock:
            self._emit(now, EventKind.DROPPED, command, reason)

    def retime(self, ids: set[int], delta: float) -> int:
        """Move the queued commands in `ids` delta s later (their speech started late); how many moved."""
        with self._lock:
            moved = [k for k, command in enumerate(self._queue) if command.id in ids]
            for k in moved:
                self._queue[k] = replace(self._queue[k], release_at=self._queue[k].release_at + delta)
            return len(moved)

    @property
    def pending(self) -> list[GestureCommand]:
        with self._lock:
            return list(self._queue)

    def _emit(self, now: float, kind: EventKind, command: GestureCommand | None, detail: str = "") -> None:
        event = Event(now, kind, command.name if command else "", command.id if command else None, detail)
        self.events.append(event)
        if self.on_event is not None:
            self.on_event(event)
