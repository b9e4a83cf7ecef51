"""Injected time: the sequencer and schedulers never call time.* directly."""

from __future__ import annotations

import threading
import time
from typing import Protocol


class Clock(Protocol):
    def now(self) -> float:
        """Seconds on a monotonic timeline."""

    def sleep_until(self, deadline: float) -> None:
        """Block until now() >= deadline."""


class MonotonicClock:
    """Wall time for real loops. Sleeps coarsely, then spins the last stretch for sub-ms deadlines."""

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
