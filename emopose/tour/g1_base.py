"""The real G1's base as a MobileBase: velocity through the loco RPC, pose from onboard odometry;
G1TourBase opens it for the tour (tour/base=g1).

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
from typing import TYPE_CHECKING

from emopose.backends.base import Backend
from emopose.scene.geometry import Pose2D, wrap_angle
from emopose.tour.scenario import TourConfigError, TourSpec

if TYPE_CHECKING:
    from emopose.backends.g1.loco import LocoClient

# (loco client, backend) -> a callable returning the robot's odometry pose on its own frame
OdometryFactory = Callable[["LocoClient", Backend], Callable[[], Pose2D]]


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


class G1TourBase:
    """tour/base=g1: the loco client on the backend's DDS domain and interface, walking on onboard odometry
    within the scenario's speed limits. close() closes the client (the runner has stopped the base)."""

    def __init__(self, domain_id: int, network_interface: str | None,
                 odometry: OdometryFactory | None = None) -> None:
        self.domain_id, self.network_interface, self.odometry = domain_id, network_interface, odometry
        self._loco: LocoClient | None = None

    def open(self, backend: Backend, spec: TourSpec) -> G1Base:
        if self.odometry is None:
            raise TourConfigError("the tour on the G1 walks on onboard odometry: set job.base.odometry to "
                                  "a factory (loco, backend) -> callable returning a "
                                  "emopose.scene.geometry.Pose2D "
                                  "({_target_: module.factory, _partial_: true})")
        from emopose.backends.g1 import LocoClient  # imports cyclonedds

        self._loco = LocoClient(domain_id=self.domain_id, network_interface=self.network_interface,
                                max_vx=spec.navigation.max_vx, max_omega=spec.navigation.max_wz).open()
        return G1Base(self._loco, self.odometry(self._loco, backend), origin=spec.start.pose())

    def close(self) -> None:
        if self._loco is not None:
            self._loco.close()
            self._loco = None
