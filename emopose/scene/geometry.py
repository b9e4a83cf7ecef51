"""Planar poses and the small geometry the tour needs: angle wrapping, map <-> torso frames, clearance.

Map frame: x forward from the tour's start, y to the left, z up, yaw counter-clockwise (radians).
The arm kinematics (emopose.robot.kinematics) work in the `torso_link` frame, which sits
TORSO_HEIGHT above the floor straight over the base origin and turns with the base's yaw.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# Pelvis 0.79 m above the floor (g1.md) + torso_link 0.05 m above the waist joint (the MJCF).
TORSO_HEIGHT = 0.84


def wrap_angle(angle: float) -> float:
    """Into [-pi, pi): the shortest turn."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


@dataclass(frozen=True)
class Pose2D:
    x: float
    y: float
    yaw: float  # radians

    def distance_to(self, other: Pose2D) -> float:
        return math.hypot(other.x - self.x, other.y - self.y)

    def bearing_to(self, other: Pose2D) -> float:
        """Heading (map frame) that faces `other` from here."""
        return math.atan2(other.y - self.y, other.x - self.x)

    def heading_error_to(self, other: Pose2D) -> float:
        return wrap_angle(other.yaw - self.yaw)

    def as_dict(self) -> dict:
        return {"x": self.x, "y": self.y, "yaw_deg": math.degrees(self.yaw)}


def map_to_torso(point: np.ndarray, base: Pose2D) -> np.ndarray:
    """A map-frame point (3,) in the torso_link frame of a robot standing at `base`."""
    c, s = math.cos(base.yaw), math.sin(base.yaw)
    dx, dy = point[0] - base.x, point[1] - base.y
    return np.array([c * dx + s * dy, -s * dx + c * dy, point[2] - TORSO_HEIGHT])


def torso_to_map(point: np.ndarray, base: Pose2D) -> np.ndarray:
    c, s = math.cos(base.yaw), math.sin(base.yaw)
    return np.array([base.x + c * point[0] - s * point[1], base.y + s * point[0] + c * point[1],
                     point[2] + TORSO_HEIGHT])


def box_clearance(point_xy: np.ndarray, center_xy: np.ndarray, half_xy: np.ndarray) -> float:
    """Distance from a floor point to an axis-aligned box footprint (0 inside it)."""
    outside = np.maximum(np.abs(np.asarray(point_xy) - center_xy) - half_xy, 0.0)
    return float(np.hypot(*outside))


def segment_clearance(a_xy: np.ndarray, b_xy: np.ndarray, center_xy: np.ndarray, half_xy: np.ndarray,
                      step_m: float = 0.02) -> float:
    """Smallest clearance from a straight leg a -> b to a box footprint (sampled every step_m)."""
    a, b = np.asarray(a_xy, float), np.asarray(b_xy, float)
    count = max(2, int(np.linalg.norm(b - a) / step_m) + 2)
    return min(box_clearance(a + f * (b - a), center_xy, half_xy) for f in np.linspace(0.0, 1.0, count))


def angle_between(u: np.ndarray, v: np.ndarray) -> float:
    """Angle in radians between two 3-vectors (robust near 0 and pi)."""
    u, v = np.asarray(u, float), np.asarray(v, float)
    return float(math.atan2(np.linalg.norm(np.cross(u, v)), float(np.dot(u, v))))
