"""The 50 Hz loop: ticks the sequencer on absolute deadlines and hands each target to the backend.

Deadline n is t0 + n * dt, so lateness never accumulates (no drift from sleep(dt) chains). With a
FakeClock the same loop renders a run as fast as the CPU allows; with MonotonicClock it is real time.
`run_until()` drives it on the caller's thread; `start()`/`stop()` run it on a background thread for
the web UI, speech and the tour; `wait_until()` waits the right way for either.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from emopose import CONTROL_DT
from emopose.backends.base import Backend
from emopose.clock import Clock
from emopose.recording import Recorder
from emopose.sequencer import Sequencer

log = logging.getLogger(__name__)


@dataclass
class LoopStats:
    ticks: int = 0
    missed_deadlines: int = 0
    lateness_s: list[float] = field(default_factory=list)

    def summary(self) -> dict:
        late = np.asarray(self.lateness_s or [0.0]) * 1e3
        return {"ticks": self.ticks, "missed_deadlines": self.missed_deadlines,
                "lateness_ms_p50": float(np.percentile(late, 50)),
                "lateness_ms_p99": float(np.percentile(late, 99)), "lateness_ms_max": float(late.max())}


class ControlLoop:
    def __init__(self, sequencer: Sequencer, backend: Backend, clock: Clock, dt: float = CONTROL_DT) -> None:
        self.sequencer, self.backend, self.clock, self.dt = sequencer, backend, clock, dt
        self.recorder: Recorder | None = None
        self.stats = LoopStats()
        self._t0: float | None = None
        self._tick = 0
        self._thread: threading.Thread | None = None
        self._stop = threading.Event()
        self.error: BaseException | None = None

    def begin(self, q0: np.ndarray, recorder: Recorder | None = None) -> None:
        """Start the stream at the measured pose q0, recording every command to `recorder`."""
        self.recorder = recorder
        self._t0 = self.clock.now()
        self._tick = 0
        self.sequencer.reset(q0, self._t0)

    @property
    def stream_time(self) -> float:
        return self.clock.now() - (self._t0 or 0.0)

    def tick(self) -> np.ndarray:
        deadline = self._t0 + (self._tick + 1) * self.dt
        self.clock.sleep_until(deadline)
        lateness = self.clock.now() - deadline
        self._tick += 1
        self.stats.ticks += 1
        self.stats.lateness_s.append(lateness)
        if lateness > self.dt:
            self.stats.missed_deadlines += 1
        q = self.sequencer.step(deadline)
        t = deadline - self._t0
        self.backend.send(t, q)
        if self.recorder is not None:
            self.recorder.write("/joints/command", t, {"t": t, "q": q.tolist()})
        return q

    def run_until(self, done: Callable[[], bool], timeout_s: float) -> bool:
        """Tick until done() (checked after each tick) or timeout (stream seconds). True if done."""
        end = self.stream_time + timeout_s
        while self.stream_time < end:
            self.tick()
            if done():
                return True
        return False

    def wait_until(self, done: Callable[[], bool], timeout_s: float) -> bool:
        """done() within timeout_s: polled (wall time) while the loop runs on its thread, else ticked here."""
        if not self.running:
            return self.run_until(done, timeout_s)
        end = time.monotonic() + timeout_s
        while time.monotonic() < end:
            if done():
                return True
            if self.error is not None:
                raise RuntimeError("control loop failed") from self.error
            time.sleep(0.01)
        return False

    # -- background thread ---------------------------------------------------------------------
    def start(self) -> None:
        if self._thread is not None:
            return
        self._stop.clear()
        self._thread = threading.Thread(target=self._run, name="emopose-control", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        try:
            while not self._stop.is_set():
                self.tick()
        except BaseException as exc:  # surfaced to the owner; the backend's close() does the safe release
            self.error = exc
            log.exception("control loop stopped")

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=2.0)
            self._thread = None

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()
