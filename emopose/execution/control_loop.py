"""The 50 Hz loop: ticks the sequencer on absolute deadlines and hands each target to the backend.

The loop records, on /joints/command, what the backend says it sent (the target after its clamping).
Its deadlines follow the one policy of every command stream (emopose/execution/pacing.py): after a stall
(or while nobody drove the loop, e.g. the planner was thinking) missed deadlines are skipped, not sent in
a burst, and counted; no command follows the previous one by less than half a period. The sequencer
samples its motions on the clock and re-times a running gesture after a skip (within the speed bound),
so a stall never jumps the arm and need not delay the stroke.
With a FakeClock the same loop renders a run as fast as the CPU allows; with MonotonicClock it is
real time. `run_until()` drives it on the caller's thread; `start()`/`stop()` run it on a background
thread for the web UI, speech and the tour; `wait_until()` waits the right way for either.
Served, the loop shares its process with the web server, planning and synthesis (frames and espeak render
in child processes); `start(rt_priority)` puts its thread in SCHED_FIFO (priority.py: else a negative
nice, else as it was, with one log line), the process's other threads in SCHED_RR below it, and shortens
Python's thread switch interval, so neither the OS nor the GIL keeps it waiting for long.
"""

from __future__ import annotations

import logging
import sys
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from emopose import CONTROL_DT
from emopose.backends.base import Backend
from emopose.clock import Clock
from emopose.execution.collector import CollectorPauses, freeze_survivors
from emopose.execution.pacing import DeadlineGrid
from emopose.execution.priority import normal_scheduling, raise_process_priority, raise_thread_priority
from emopose.execution.sequencer import Sequencer
from emopose.execution.worker import Worker
from emopose.recording import Recorder

log = logging.getLogger(__name__)

RT_SWITCH_INTERVAL_S = 0.0005  # GIL hand-over interval while the loop runs on its thread (Python: 5 ms)


@dataclass
class LoopStats:
    """Counters over the whole run, and the lateness of the last `window` ticks (a long serve must not
    grow a list forever): percentiles are over that window, the maximum over the whole run."""

    window: int = 3000  # one minute at 50 Hz
    ticks: int = 0
    missed_deadlines: int = 0  # deadlines skipped because the loop fell behind while it was driven
    stalls: int = 0  # how often it fell behind by a whole period and re-anchored
    idle_ticks: int = 0  # deadlines skipped while nobody drove the loop (between run_until calls)
    scheduling: str = "normal"  # what the loop thread got from the OS (see raise_thread_priority)
    lateness_max_s: float = 0.0
    lateness_s: deque[float] = field(init=False, repr=False)
    collector: CollectorPauses = field(default_factory=CollectorPauses, repr=False)  # timed in real-time runs

    def __post_init__(self) -> None:
        self.lateness_s = deque(maxlen=self.window)

    def add(self, lateness: float) -> None:
        self.ticks += 1
        self.lateness_s.append(lateness)
        self.lateness_max_s = max(self.lateness_max_s, lateness)

    def summary(self) -> dict:
        # list() copies in one C call while the loop thread may append (web status reads it live)
        late = np.asarray(list(self.lateness_s) or [0.0]) * 1e3
        return {"ticks": self.ticks, "missed_deadlines": self.missed_deadlines, "stalls": self.stalls,
                "missed_per_tick": self.missed_deadlines / max(self.ticks, 1), "idle_ticks": self.idle_ticks,
                "scheduling": self.scheduling, "lateness_ms_p50": float(np.percentile(late, 50)),
                "lateness_ms_p99": float(np.percentile(late, 99)),
                "lateness_ms_max": self.lateness_max_s * 1e3, **self.collector.summary()}


class ControlLoop:
    def __init__(self, sequencer: Sequencer, backend: Backend, clock: Clock, dt: float = CONTROL_DT) -> None:
        self.sequencer, self.backend, self.clock, self.dt = sequencer, backend, clock, dt
        self.recorder: Recorder | None = None
        self.stats = LoopStats()
        self._grid = DeadlineGrid(clock, dt)
        self._begun = False
        self._resuming = True  # nobody drove the loop since the last tick: lag is idle time, not a stall
        self._worker = Worker("emopose-control", self._run, join_timeout_s=2.0)
        self._rt_priority = 0
        self._saved_switch_interval: float | None = None
        self._process_scheduling = "process nice unchanged"
        self.error: BaseException | None = None
        sequencer.stroke_watch.measuring = backend.measures_joints  # STROKE from the measured joints

    def begin(self, q0: np.ndarray, recorder: Recorder | None = None) -> None:
        """Start the stream at the measured pose q0, recording every command to `recorder`."""
        self.recorder = recorder
        self._grid.restart(self.clock.now())
        self._begun = True
        self._resuming = True
        self.sequencer.reset(q0, self._t0)
        if recorder is not None:
            if recorder.clock is not self.clock:
                raise ValueError("control loop: the recorder must run on the loop's clock (one time base)")
            recorder.start_stream(self._t0)

    @property
    def _t0(self) -> float:
        """The stream's zero on the clock (0 before begin())."""
        return self._grid.t0 if self._begun else 0.0

    @property
    def stream_time(self) -> float:
        return self.clock.now() - self._t0

    def stream_time_of(self, clock_time: float) -> float:
        """A time read from the loop's clock, on the stream's time base (the `t` of /joints/command)."""
        return clock_time - self._t0

    def tick(self) -> np.ndarray:
        """Wait for the next deadline, send the sequencer's target; returns (and records) what was sent."""
        behind = self._grid.skip_missed()
        if behind > 0:
            if self._resuming:
                self.stats.idle_ticks += behind
            else:
                self.stats.missed_deadlines += behind
                self.stats.stalls += 1
        self._resuming = False
        self.clock.sleep_until(self._grid.send_at())
        deadline = self._grid.take()
        self.stats.add(self.clock.now() - deadline)
        t = deadline - self._t0
        sent = self.backend.send(t, self.sequencer.step(deadline))
        self._grid.sent()
        if self.recorder is not None:
            self.recorder.write("/joints/command", t, {"t": t, "q": sent.tolist()})
        if self.backend.measures_joints and (measured := self.backend.measured()) is not None:
            self.sequencer.observe(deadline + self.backend.measured_lead_s, measured)
        return sent

    def run_until(self, done: Callable[[], bool], timeout_s: float) -> bool:
        """Tick until done() (checked after each tick) or timeout (stream seconds). True if done.
        Time since the previous drive (a planner call, say) is idle, skipped at the first tick."""
        self._resuming = True
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
    def start(self, rt_priority: int = 0) -> None:
        """Run the loop on its thread; rt_priority > 0 (run.rt_priority, real-time runs) raises the thread's
        scheduling, hands the GIL over every RT_SWITCH_INTERVAL_S until stop(), freezes what set-up left for
        the garbage collector and times its pauses (emopose/execution/collector.py): call it once loaded."""
        self._rt_priority = rt_priority
        if rt_priority > 0 and self._saved_switch_interval is None:
            self._saved_switch_interval = sys.getswitchinterval()
            sys.setswitchinterval(RT_SWITCH_INTERVAL_S)
            self._process_scheduling = raise_process_priority()
            freeze_survivors()
            self.stats.collector.install()
        self._worker.start()

    def _run(self, stop: threading.Event) -> None:
        if self._rt_priority > 0:
            self.stats.scheduling = f"{raise_thread_priority(self._rt_priority)}; {self._process_scheduling}"
        try:
            while not stop.is_set():
                self.tick()
        except BaseException as exc:  # surfaced to the owner; the backend's close() does the safe release
            self.error = exc
            log.exception("control loop stopped")

    def stop(self) -> None:
        self._worker.stop()
        self.stats.collector.remove()
        if self._saved_switch_interval is not None:
            sys.setswitchinterval(self._saved_switch_interval)
            self._saved_switch_interval = None
            normal_scheduling()  # what runs after (a tour's video, say) competes like any other work

    @property
    def running(self) -> bool:
        return self._worker.running
