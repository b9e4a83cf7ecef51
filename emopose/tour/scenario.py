"""A tour scenario (conf/tour/*.yaml): stops, route, objects of interest, scripted interruptions.

Validated with pydantic when loaded; every problem is reported as `<file>: <where>: <what>`, where
names the stop (by position and name) and the field, e.g.
    conf/tour/lab.yaml: stops[2] 'mocap_area'.pose.x: Field required
Besides field types, the scenario is checked as a whole: unique names, the route and the
interruptions name known stops, point_at names one of the stop's objects, every stop lies inside the
arena (minus the robot's radius), and no stop or straight leg runs through an object's footprint.
"""

from __future__ import annotations

import math

from pydantic import BaseModel, ConfigDict, Field, model_validator

from emopose.contract import MAX_REPLY_CHARS
from emopose.scene.geometry import Pose2D

NAME = r"^[a-z][a-z0-9_]{0,63}$"


class TourConfigError(ValueError):
    """A tour scenario cannot be used; the message names the file, the stop and the field."""


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class PoseSpec(_Strict):
    x: float
    y: float
    yaw_deg: float = 0.0

    def pose(self) -> Pose2D:
        return Pose2D(self.x, self.y, math.radians(self.yaw_deg))


class ObjectSpec(_Strict):
    """Something at a stop the robot can point at and the head camera can see (a box in simulation)."""

    name: str = Field(pattern=NAME)
    position: tuple[float, float, float]  # map frame, m: the point a pointing gesture aims at
    size: tuple[float, float, float] = (0.15, 0.15, 0.15)  # half extents of the simulated box, m
    color: tuple[float, float, float] = (0.85, 0.35, 0.2)
    aliases: tuple[str, ...] = ()  # words that name it in speech ("the cameras")
    description: str | None = None

    def words(self) -> tuple[str, ...]:
        return (self.name.replace("_", " "), *self.aliases)


class StopSpec(_Strict):
    name: str = Field(pattern=NAME)
    title: str | None = None
    pose: PoseSpec
    narration: str = Field(min_length=1)  # any length: planned and spoken in chunks of whole sentences
    approach: str | None = Field(default=None, max_length=MAX_REPLY_CHARS)  # said while walking to this stop
    objects: tuple[ObjectSpec, ...] = ()
    point_at: str | None = None  # default pointing target when the stop has several objects


class InterruptionSpec(_Strict):
    """A visitor speaking at a stop (during its narration) or during the leg that leads to a stop."""

    text: str = Field(min_length=1, max_length=MAX_REPLY_CHARS)
    at_stop: str | None = None
    during_leg: str | None = None  # the stop this leg leads to
    after_s: float = Field(default=0.0, ge=0.0)  # into the narration / the leg
    answer: str | None = Field(default=None, max_length=MAX_REPLY_CHARS)  # said by narrating planners

    @model_validator(mode="after")
    def _one_place(self) -> InterruptionSpec:
        if (self.at_stop is None) == (self.during_leg is None):
            raise ValueError("give exactly one of at_stop or during_leg")
        return self


class ArenaSpec(_Strict):
    x: tuple[float, float]
    y: tuple[float, float]


class NavigationSpec(_Strict):
    max_vx: float = Field(default=0.3, gt=0.0, le=0.3)  # m/s: conservative indoor walking (g1.md)
    max_wz: float = Field(default=0.5, gt=0.0, le=1.0)  # rad/s
    stop_tolerance_m: float = Field(default=0.10, gt=0.0)
    yaw_tolerance_deg: float = Field(default=4.0, gt=0.0)
    leg_timeout_s: float = Field(default=120.0, gt=0.0)


class OdometryNoiseSpec(_Strict):
    """Gaussian noise on the velocities the simulated odometry integrates (0 = perfect odometry)."""

    velocity_std: float = Field(default=0.0, ge=0.0)  # m/s per control tick
    yaw_rate_std: float = Field(default=0.0, ge=0.0)  # rad/s per control tick
    seed: int = 0


class TourSpec(_Strict):
    name: str = Field(pattern=NAME)
    arena: ArenaSpec
    start: PoseSpec = PoseSpec(x=0.0, y=0.0)
    robot_radius_m: float = Field(default=0.3, gt=0.0)
    stops: tuple[StopSpec, ...] = Field(min_length=1)
    route: tuple[str, ...] | None = None  # stop names in visiting order; default: the stops as listed
    interruptions: tuple[InterruptionSpec, ...] = ()
    closing: str | None = Field(default=None, max_length=MAX_REPLY_CHARS)  # said after the last stop
    abort_reply: str = Field(default="Of course, we will end the tour here. Thank you for visiting!",
                             min_length=1, max_length=MAX_REPLY_CHARS)
    gesture_while_walking: bool = False
    navigation: NavigationSpec = NavigationSpec()
    odometry_noise: OdometryNoiseSpec = OdometryNoiseSpec()

    @property
    def stops_in_order(self) -> list[StopSpec]:
        by_name = {s.name: s for s in self.stops}
        return [by_name[n] for n in (self.route or [s.name for s in self.stops])]

    def stop(self, name: str) -> StopSpec:
        return next(s for s in self.stops if s.name == name)

    @property
    def objects(self) -> list[ObjectSpec]:
        return [o for s in self.stops for o in s.objects]
