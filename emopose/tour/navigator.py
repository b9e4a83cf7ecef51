"""Navigation: a mobile base the tour can drive, and the loop that drives it to a stop.

A `MobileBase` is what both the MuJoCo planar base (sim_base.py) and the G1's loco service
(g1_base.py) offer: an odometry pose, a body-frame velocity command, stop. `Navigator.go_to` runs
the GoToPose controller on odometry, one control period per `advance()` call; a visitor's question
(from `poll`) brings the base to rest before it is answered, then the leg resumes from where it stopped.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

from emopose import CONTROL_DT
from emopose.scene.geometry import Pose2D
from emopose.tour.controller import GoToPose


@runtime_checkable
class MobileBase(Protocol):
    def odometry(self) -> Pose2D:
        """The base's own estimate of its pose in the map frame (what the controller sees)."""

    def command(self, vx: float, wz: float) -> None:
        """Body-frame forward speed (m/s) and yaw rate (rad/s)."""

    def stop(self) -> None:
        """Command zero velocity now."""

    def moving(self) -> bool:
        """Whether the base still moves (after stop(), until it has come to rest)."""

    def after_tick(self, dt: float) -> None:
        """Called once per control period after the world advanced (odometry integration)."""


@runtime_checkable
class GroundTruthBase(Protocol):
    """A base that also knows where it really is (a simulator): used only to score the tour."""

    def true_pose(self) -> Pose2D: ...


@dataclass(frozen=True)
class NavigationSettings:
    max_vx: float = 0.3
    max_wz: float = 0.5
    stop_tolerance_m: float = 0.10
    yaw_tolerance_deg: float = 4.0
    leg_timeout_s: float = 120.0


@dataclass(frozen=True)
class LegResult:
    goal: Pose2D
    reached: bool
    odometry: Pose2D  # where the base believes it stopped
    duration_s: float
    pauses: int

    @property
    def odometry_error_m(self) -> float:
        return self.odometry.distance_to(self.goal)


class Navigator:
    def __init__(self, base: MobileBase, settings: NavigationSettings, advance: Callable[[], None],
                 now: Callable[[], float], dt: float = CONTROL_DT) -> None:
        self.base, self.settings, self.dt = base, settings, dt
        self._advance, self._now = advance, now

    def controller(self, goal: Pose2D) -> GoToPose:
        s = self.settings
        return GoToPose(goal, max_vx=s.max_vx, max_wz=s.max_wz, tolerance_m=s.stop_tolerance_m,
                        yaw_tolerance=math.radians(s.yaw_tolerance_deg), dt=self.dt)

    def go_to(self, goal: Pose2D, poll: Callable[[float], object | None] | None = None,
              handle: Callable[[object], bool] | None = None) -> LegResult:
        """Drive to goal. poll(elapsed_s) is asked each period for an event (a visitor's question);
        on one the base is brought to rest first, then handle(event) runs (it may speak and gesture)
        and returns whether to carry on (False aborts the leg)."""
        controller = self.controller(goal)
        started, pauses = self._now(), 0
        try:
            while not controller.done:
                elapsed = self._now() - started
                if elapsed > self.settings.leg_timeout_s:
                    break
                event = poll(elapsed) if poll is not None else None
                if event is not None:
                    self.halt()
                    pauses += 1
                    if handle is not None and not handle(event):
                        break
                    controller = self.controller(goal)  # restart the ramps from standstill
                    continue
                self.base.command(*controller.update(self.base.odometry()))
                self._advance()
        finally:
            self.halt()
        return LegResult(goal, controller.done, self.base.odometry(), self._now() - started, pauses)

    def halt(self, timeout_s: float = 3.0) -> bool:
        """Stop the base and keep the world running until it is at rest (True) or timeout."""
        self.base.stop()
        end = self._now() + timeout_s
        while self.base.moving() and self._now() < end:
            self._advance()
        return not self.base.moving()
