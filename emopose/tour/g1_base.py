"""The real G1's base as a MobileBase: velocity through the loco RPC, pose from onboard odometry.

Commands go out through emopose.backends.g1.LocoClient.set_velocity (it clamps to vx <= 0.3 m/s)
at most every `period_s`, each with a short `duration`, so the robot stops by itself within that
time if the tour process dies. Odometry is whatever `odometry()` callable the caller supplies: on
the robot a subscriber to its odometry topic, in tests the fake robot's integrated odometry.
Odometry arrives in the robot's own frame (zero where it booted); `origin` maps it onto the map.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

from emopose.scene.geometry import Pose2D, wrap_angle


class G1Base:
    def __init__(self, loco, odometry: Callable[[], Pose2D], origin: Pose2D | None = None,
                 period_s: float = 0.1, duration_s: float = 0.5, rest_after_s: float = 0.6,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.loco, self._read = loco, odometry
        self.period_s, self.duration_s, self.rest_after_s = period_s, duration_s, rest_after_s
        self._clock = clock
        self._last_sent = -math.inf
        self._last: tuple[float, float] | None = None
        self._stopped_at = -math.inf
        self._offset = Pose2D(0.0, 0.0, 0.0)
        if origin is not None:
            self.align_to(origin)

    def align_to(self, pose: Pose2D) -> None:
        """Declare the robot's current odometry reading to be `pose` on the map (start of the tour)."""
        raw = self._read()
        yaw = wrap_angle(pose.yaw - raw.yaw)
        c, s = math.cos(yaw), math.sin(yaw)
        self._offset = Pose2D(pose.x - (c * raw.x - s * raw.y), pose.y - (s * raw.x + c * raw.y), yaw)

    def odometry(self) -> Pose2D:
        raw, o = self._read(), self._offset
        c, s = math.cos(o.yaw), math.sin(o.yaw)
        return Pose2D(o.x + c * raw.x - s * raw.y, o.y + s * raw.x + c * raw.y, wrap_angle(raw.yaw + o.yaw))

    def command(self, vx: float, wz: float) -> None:
        now = self._clock()
        changed = self._last is None or abs(vx - self._last[0]) > 0.02 or abs(wz - self._last[1]) > 0.05
        # Refresh before the previous command's duration runs out, or at once on a real change.
        if changed and now - self._last_sent >= 0.5 * self.period_s or now - self._last_sent >= self.period_s:
            self.loco.set_velocity(vx, 0.0, wz, self.duration_s)
            self._last_sent, self._last = now, (vx, wz)

    def stop(self) -> None:
        if self._last != (0.0, 0.0):
            self._stopped_at = self._clock()
        self.loco.stop()
        self._last_sent, self._last = self._clock(), (0.0, 0.0)

    def moving(self) -> bool:
        # The sport service ramps down on its own; give it rest_after_s after the zero command.
        return self._last not in (None, (0.0, 0.0)) or self._clock() - self._stopped_at < self.rest_after_s

    def after_tick(self, dt: float) -> None:
        pass  # the robot integrates its own odometry
