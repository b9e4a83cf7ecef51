"""Time for the tour: one control period at a time, on a virtual or a real clock.

On a virtual clock (simulation) the tour owns the 50 Hz loop and ticks it itself, so physics, the
sequencer, the base controller and scripted questions all advance in lockstep and a run is as fast
as the CPU allows. With a real clock (the G1) the loop runs on its own thread and advance() just
waits one period. Either way the base integrates its odometry after each period, and the base's
pose goes to the MCAP recording a few times a second.
"""

from __future__ import annotations

from collections.abc import Callable

from emopose.clock import Clock
from emopose.tour.navigator import GroundTruthBase, MobileBase
from emopose.turn.session import Session


class TourWorld:
    def __init__(self, session: Session, clock: Clock, base: MobileBase, record_hz: float = 10.0) -> None:
        self.session, self.clock, self.base = session, clock, base
        self.loop = session.open()
        self.dt = self.loop.dt
        self._record_every = max(1, round(1.0 / (record_hz * self.dt)))
        self._ticks = 0

    def now(self) -> float:
        return self.clock.now()

    @property
    def stream_time(self) -> float:
        return self.loop.stream_time

    def advance(self) -> None:
        if self.loop.running:
            self.clock.sleep_until(self.clock.now() + self.dt)
            if self.loop.error is not None:
                raise RuntimeError("control loop failed") from self.loop.error
        else:
            self.loop.tick()
        self.base.after_tick(self.dt)
        self._ticks += 1
        if self._ticks % self._record_every == 0:
            self.record_base()

    def run_until(self, done: Callable[[], bool], timeout_s: float) -> bool:
        end = self.now() + timeout_s
        while not done():
            if self.now() >= end:
                return False
            self.advance()
        return True

    def record(self, topic: str, payload: dict) -> None:
        self.session.write(topic, payload)

    def record_base(self) -> None:
        self.record("/base/odometry", self.base.odometry().as_dict())
        if isinstance(self.base, GroundTruthBase):
            self.record("/base/true", self.base.true_pose().as_dict())
