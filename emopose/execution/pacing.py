"""The one deadline policy of every command stream to the robot: the control loop, and the G1 backend's
weight ramps, release and holds.

Deadline n is t0 + n * dt, so lateness never accumulates (no drift from sleep(dt) chains). Deadlines
that passed a whole period ago, or at or before the previous send (it stood for them), are skipped, not
sent in a burst: after a stall the stream re-anchors on its grid and says how many it skipped. No
command follows the previous one by less than MIN_GAP_PERIODS of a period.
"""

from __future__ import annotations

import math

from emopose.clock import Clock

MIN_GAP_PERIODS = 0.5  # the closest two commands may follow each other, in periods
TIME_EPS_S = 1e-9  # float rounding of sums of periods: a deadline this close counts as reached


class DeadlineGrid:
    def __init__(self, clock: Clock, dt: float) -> None:
        self.clock, self.dt = clock, dt
        self.t0 = clock.now()
        self.ticks = 0  # deadlines taken or skipped since t0
        self.last_sent = -math.inf  # clock time the previous command went out

    def restart(self, t0: float) -> None:
        """A new grid from t0 (the previous send still counts for the gap)."""
        self.t0, self.ticks = t0, 0

    @property
    def deadline(self) -> float:
        return self.t0 + (self.ticks + 1) * self.dt

    def skip_missed(self) -> int:
        """Skip the deadlines a whole period past or already covered by the previous send; how many."""
        covered = max(self.clock.now() - self.dt, self.last_sent)
        deadline = self.deadline
        if covered < deadline - TIME_EPS_S:
            return 0
        behind = math.floor((covered - deadline + TIME_EPS_S) / self.dt) + 1
        self.ticks += behind
        return behind

    def send_at(self) -> float:
        """When the next command may go out: its deadline, and never within the minimum gap."""
        return max(self.deadline, self.last_sent + MIN_GAP_PERIODS * self.dt)

    def due(self) -> bool:
        """Whether the next command may go out now (for a caller that polls instead of sleeping)."""
        return self.clock.now() >= self.send_at() - TIME_EPS_S

    def take(self) -> float:
        """Take the next deadline (its command goes out now); returns it."""
        deadline = self.deadline
        self.ticks += 1
        return deadline

    def wait(self) -> float:
        """Skip what was missed, sleep until the next send time, take its deadline; returns it."""
        self.skip_missed()
        self.clock.sleep_until(self.send_at())
        return self.take()

    def sent(self) -> None:
        """The command went out: the next one keeps its gap from now."""
        self.last_sent = self.clock.now()
