"""The run's lifecycle: the MCAP recorder, the backend connection and the 50 Hz control loop.

Execution opens lazily and explicitly with `open()` (idempotent), so jobs that only plan (the
benchmarks) never touch a simulator or a robot; `close()` always releases the robot and closes the
recording, whatever happened. The recorder runs on the loop's clock, so the loop's commands, the
backend's own messages and the turn's records share one time base; `origin` is its zero (the run's
start), for jobs that report times relative to the run.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from pathlib import Path

import numpy as np

from emopose.backends.base import Backend
from emopose.execution.collector import freeze_survivors
from emopose.execution.control_loop import ControlLoop
from emopose.execution.gesture_command import Event
from emopose.recording import Recorder
from emopose.sync.recording import EVENTS, event_message

log = logging.getLogger(__name__)


class Session:
    def __init__(self, backend: Backend, loop: ControlLoop, neutral: np.ndarray, run_dir: str | Path,
                 record: bool = True) -> None:
        self.backend, self.loop, self.neutral = backend, loop, np.asarray(neutral, dtype=float)
        self.run_dir, self.record = Path(run_dir), record
        self.recorder: Recorder | None = None
        self.origin: float | None = None  # loop-clock time at open(): the run's (and recording's) zero
        self._open = False

    @property
    def is_open(self) -> bool:
        return self._open

    @property
    def recording(self) -> bool:
        """Whether write() records anything: open, with a recorder."""
        return self._open and self.recorder is not None

    def open(self) -> ControlLoop:
        """Connect the backend and start the 50 Hz stream at the measured pose (idempotent)."""
        if self._open:
            return self.loop
        if self.record and self.recorder is None:
            self.recorder = Recorder(self.run_dir / "session.mcap", clock=self.loop.clock)
        if self.origin is None:
            self.origin = self.recorder.origin if self.recorder is not None else self.loop.clock.now()
        if self.loop.clock.realtime:
            freeze_survivors()  # a collector pause over set-up's objects would stall the robot's stream
        measured = self.backend.connect(self.recorder)
        q0 = self.neutral if measured is None else np.asarray(measured, dtype=float)
        self.loop.begin(q0, self.recorder)
        self._open = True
        return self.loop

    def restart(self, q0: np.ndarray) -> None:
        """Start the stream afresh at q0 (after the caller re-posed a simulator): stream time from zero."""
        self.open()
        self.loop.begin(np.asarray(q0, dtype=float), self.recorder)

    def tap(self, wrap: Callable[[Backend], Backend]) -> Backend:
        """Route the stream through wrap(backend) from now on (a measurement tap); returns the wrapper."""
        self.loop.backend = wrap(self.loop.backend)
        return self.loop.backend

    def write(self, topic: str, payload: dict) -> None:
        """Record a message at the current time (nothing before open() or without a recorder)."""
        if self.recording:
            self.recorder.write_now(topic, payload)

    def record_at(self, topic: str, clock_time: float, payload: dict) -> None:
        """Record a message at a loop-clock time (now or ahead: a clip's samples as they will be heard);
        its `t` is that time on the session clock."""
        if self.recording:
            self.recorder.write(topic, self.loop.stream_time_of(clock_time), payload)

    def record_event(self, event: Event) -> None:
        """The sequencer's on_event callback: each event on /sequencer/events, on the stream's time base.
        Payload and log time are both the event's own time (one clock read), so they never disagree."""
        if self.recording:
            t = self.loop.stream_time_of(event.t)
            self.recorder.write(EVENTS, t, event_message(event, t))

    def run_time(self, clock_time: float) -> float:
        """Seconds since the run started (open()) of a time read from the loop's clock."""
        if self.origin is None:
            raise RuntimeError("session: run_time() before open()")
        return clock_time - self.origin

    def close(self) -> None:
        try:
            if self._open:
                self.loop.stop()
            self.backend.close()
        finally:
            if self.recorder is not None:
                self.recorder.close()

    def __enter__(self) -> Session:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
