"""Go-to-pose velocity controller: turn to face the goal, drive to it, turn to the goal's heading.

Output is a body-frame command (vx, wz) like the G1 sport service takes; it sees only odometry, so
the same controller drives the MuJoCo base and the real robot. Driving keeps steering toward the goal
but, inside `final_approach_m`, holds its heading and closes only the along-track distance: near
the goal the bearing swings wildly with every centimetre of error, and chasing it makes the base
spin in place. Speeds ramp with `max_accel` so a start or stop never jerks the arms.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

from emopose.robot.g1_spec import CONTROL_DT
from emopose.scene.geometry import Pose2D, wrap_angle

Phase = Literal["turn", "drive", "align", "done"]


@dataclass
class GoToPose:
    goal: Pose2D
    max_vx: float = 0.3
    max_wz: float = 0.5
    tolerance_m: float = 0.10
    yaw_tolerance: float = math.radians(4.0)
    max_accel: float = 0.6  # m/s^2
    max_yaw_accel: float = 1.5  # rad/s^2
    heading_gain: float = 1.5
    distance_gain: float = 1.0
    final_approach_m: float = 0.2
    dt: float = CONTROL_DT
    phase: Phase = "turn"
    _vx: float = field(default=0.0, repr=False)
    _wz: float = field(default=0.0, repr=False)

    def __post_init__(self) -> None:
        if not 0.0 < self.max_vx <= 0.3:
            raise ValueError(f"navigation max_vx must be in (0, 0.3] m/s indoors, got {self.max_vx}")
        # Stop well inside the tolerance so odometry noise and the braking ramp leave margin.
        self._arrive_m = min(0.03, 0.3 * self.tolerance_m)

    @property
    def done(self) -> bool:
        return self.phase == "done"

    def update(self, odom: Pose2D) -> tuple[float, float]:
        """One control period: the (vx m/s, wz rad/s) to command given the odometry pose."""
        distance = odom.distance_to(self.goal)
        vx, wz = 0.0, 0.0
        if self.phase == "turn" and distance <= self._arrive_m:
            self.phase = "align"
        if self.phase == "turn":
            error = wrap_angle(odom.bearing_to(self.goal) - odom.yaw)
            if abs(error) >= math.radians(2.0):
                wz = self._turn_rate(error)
            elif abs(self._wz) < 0.05:  # facing the goal and the turn has wound down
                self.phase = "drive"
        elif self.phase == "drive":
            vx, wz = self._drive(odom, distance)
        elif self.phase == "align":
            error = odom.heading_error_to(self.goal)
            if distance > self.tolerance_m:  # drifted off while turning: approach again
                self.phase = "turn"
            elif abs(error) > 0.25 * self.yaw_tolerance:
                wz = self._turn_rate(error)
            elif abs(self._wz) < 0.02 and abs(self._vx) < 0.01:
                self.phase = "done"
        return self._ramp(vx, wz)

    def _drive(self, odom: Pose2D, distance: float) -> tuple[float, float]:
        bearing_error = wrap_angle(odom.bearing_to(self.goal) - odom.yaw)
        if distance > self.final_approach_m:
            wz = self._turn_rate(bearing_error)
            # Slow down while the heading is off; never back up in this phase.
            vx = min(self.max_vx, self.distance_gain * distance) * max(0.0, math.cos(bearing_error))
            return vx, wz
        along = distance * math.cos(bearing_error)
        if along <= 0.005:  # the braking ramp covers the last few millimetres
            self.phase = "align"
            return 0.0, 0.0
        return max(0.05, min(self.max_vx, self.distance_gain * along)), 0.0

    def _turn_rate(self, error: float) -> float:
        # Proportional with a floor so the last degrees do not take forever.
        rate = self.heading_gain * error
        if abs(rate) < 0.08:
            rate = math.copysign(0.08, error) if abs(error) > math.radians(0.5) else 0.0
        return max(-self.max_wz, min(self.max_wz, rate))

    def _ramp(self, vx: float, wz: float) -> tuple[float, float]:
        dv, dw = self.max_accel * self.dt, self.max_yaw_accel * self.dt
        self._vx += max(-dv, min(dv, vx - self._vx))
        self._wz += max(-dw, min(dw, wz - self._wz))
        return self._vx, self._wz
