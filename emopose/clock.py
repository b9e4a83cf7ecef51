"""Injected time: the sequencer and schedulers never call time.* directly."""

from __future__ import annotations

import threading
import time
from typing import Protocol

CLOCK_SETTINGS = ("auto", "monotonic", "virtual")


class Clock(Protocol):
    """realtime: now() follows the wall clock (audio devices, a robot and a browser see the same time);
    False for virtual time, which only moves when something sleeps on it."""

    realtime: bool

    def now(self) -> float:
        """Seconds on a monotonic timeline."""

    def sleep_until(self, deadline: float) -> None:
        """Block until now() >= deadline."""


class MonotonicClock:
    """Wall time for real loops. Sleeps coarsely, then spins the last stretch for sub-ms deadlines."""

    realtime = True
    spin_s = 0.0015

    def now(self) -> float:
        return time.perf_counter()

    def sleep_until(self, deadline: float) -> None:
        remaining = deadline - time.perf_counter()
        if remaining > self.spin_s:
            time.sleep(remaining - self.spin_s)
        while time.perf_counter() < deadline:
            pass


class FakeClock:
    """Virtual time for tests and offline rendering: sleeping advances time instantly."""

    realtime = False

    def __init__(self, start: float = 0.0) -> None:
        self._t = start
        self._lock = threading.Lock()

    def now(self) -> float:
        with self._lock:
            return self._t

    def sleep_until(self, deadline: float) -> None:
        with self._lock:
            self._t = max(self._t, deadline)

    def advance(self, seconds: float) -> None:
        with self._lock:
            self._t += seconds


def clock_for(setting: str, backend_needs_realtime: bool) -> Clock:
    """run.clock -> the clock: monotonic (wall time), virtual, or auto (wall time only for a backend that
    needs it). A real robot never runs on virtual time: its commands would go out as fast as they are made."""
    if setting not in CLOCK_SETTINGS:
        raise ValueError(f"run.clock={setting!r} is not a clock; choose one of {', '.join(CLOCK_SETTINGS)}")
    if setting == "virtual" and backend_needs_realtime:
        raise ValueError("run.clock=virtual: this backend drives a real robot, which needs wall time "
                         "(run.clock=auto or monotonic)")
    realtime = setting == "monotonic" or (setting == "auto" and backend_needs_realtime)
    return MonotonicClock() if realtime else FakeClock()
