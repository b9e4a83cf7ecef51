"""The simulated planar base (a PlanarBase, e.g. the MuJoCo backend's) as a MobileBase, with dead-reckoning
odometry; SimTourBase opens it for the tour (tour/base=sim).

Odometry integrates the base's body-frame velocity each control period, as leg odometry does,
with optional seeded Gaussian noise on the velocities, so it drifts from the simulated truth the
way a real robot's does; `true_pose()` is the simulator's ground truth, used only to score the tour.
Call place() and the odometry before the control loop runs on another thread (the tour drives the
simulation on its own thread).
"""

from __future__ import annotations

import math

import numpy as np

from emopose.backends.base import Backend
from emopose.backends.capabilities import PlanarBase, SimulatedState
from emopose.scene.geometry import Pose2D, wrap_angle
from emopose.tour.scenario import TourConfigError, TourSpec


class MujocoBase:
    def __init__(self, base: PlanarBase, velocity_std: float = 0.0, yaw_rate_std: float = 0.0, seed: int = 0,
                 rest_speed: float = 0.01) -> None:
        """`base`: the connected simulator's planar base (open the session first)."""
        self.base = base
        self.velocity_std, self.yaw_rate_std = velocity_std, yaw_rate_std
        self.rest_speed = rest_speed
        self._rng = np.random.default_rng(seed)
        self._commanded = False  # a non-zero velocity command is in force
        self._settled = True  # at rest since the last stop (arm reactions at a stop are not walking)
        self._odom = self.true_pose()
        self.travelled_m = 0.0

    # -- ground truth ------------------------------------------------------------------------
    def true_pose(self) -> Pose2D:
        x, y, yaw = self.base.pose()
        return Pose2D(x, y, wrap_angle(yaw))

    def true_velocity(self) -> tuple[float, float, float]:
        """Body-frame (vx, vy, wz) of the simulated base."""
        return self.base.velocity()

    def place(self, pose: Pose2D) -> None:
        """Teleport the base (at rest) and reset odometry to it: the start of a tour or a trial."""
        self.base.place(pose.x, pose.y, pose.yaw)
        self._odom = pose
        self._commanded, self._settled = False, True

    # -- MobileBase ----------------------------------------------------------------------------
    def odometry(self) -> Pose2D:
        return self._odom

    def command(self, vx: float, wz: float) -> None:
        self.base.set_velocity(float(vx), 0.0, float(wz))
        self._commanded, self._settled = (vx, wz) != (0.0, 0.0), False

    def stop(self) -> None:
        self.base.set_velocity(0.0, 0.0, 0.0)
        self._commanded, self._settled = False, False

    def moving(self) -> bool:
        """Walking: a velocity command is in force, or the base has not yet come to rest after the last
        one. Once at rest, the sway the arms' reaction forces give the simulated base does not count."""
        return self._commanded or not (self._settled or self._at_rest())

    def _at_rest(self) -> bool:
        vx, vy, wz = self.true_velocity()
        return math.hypot(vx, vy) <= self.rest_speed and abs(wz) <= 2 * self.rest_speed

    def after_tick(self, dt: float) -> None:
        self._settled = self._settled or (not self._commanded and self._at_rest())
        vx, vy, wz = self.true_velocity()
        if self.velocity_std or self.yaw_rate_std:
            moving = math.hypot(vx, vy) > 1e-3 or abs(wz) > 1e-3  # no drift while standing still
            if moving:
                vx += self._rng.normal(0.0, self.velocity_std)
                vy += self._rng.normal(0.0, self.velocity_std)
                wz += self._rng.normal(0.0, self.yaw_rate_std)
        o = self._odom
        yaw_mid = o.yaw + 0.5 * wz * dt  # midpoint heading: exact for constant-curvature arcs
        c, s = math.cos(yaw_mid), math.sin(yaw_mid)
        self._odom = Pose2D(o.x + (c * vx - s * vy) * dt, o.y + (s * vx + c * vy) * dt,
                            wrap_angle(o.yaw + wz * dt))
        self.travelled_m += math.hypot(vx, vy) * dt


class SimTourBase:
    """tour/base=sim: the simulated backend's planar base, placed at the tour's start, its odometry
    as noisy as the scenario says."""

    def open(self, backend: Backend, spec: TourSpec) -> MujocoBase:
        planar = backend.planar_base if isinstance(backend, SimulatedState) else None
        if not isinstance(planar, PlanarBase):
            raise TourConfigError(f"tour/base=sim needs a simulated planar base: backend={backend.name} "
                                  "has none; use backend=mujoco with a backend.planar_base (as "
                                  "+experiment=tour_lab sets), or tour/base=g1 on the robot")
        noise = spec.odometry_noise
        base = MujocoBase(planar, noise.velocity_std, noise.yaw_rate_std, noise.seed)
        base.place(spec.start.pose())
        return base

    def close(self) -> None:
        """Nothing to release: the simulator owns its base."""
