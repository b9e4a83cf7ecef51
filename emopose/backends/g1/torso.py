"""The gravity feed-forward under the measured torso: the arms hang from torso_link, which the waist
(yaw, roll, pitch: motors 12-14) and the pelvis (LowState_'s IMU roll and pitch) tilt.

The project's MJCF holds the torso upright (fixed base, waist fixed); tilting the torso is the same, for
the arms' gravity torque at zero velocity, as turning gravity the other way in the torso's frame. So
G(q) is the model's, with gravity g_torso = R^T g, R = Ry(imu pitch) Rx(imu roll) Rz(waist yaw)
Rx(waist roll) Ry(waist pitch): the pelvis in the world (its yaw does not change gravity), then the
waist chain as Unitree's g1_29dof model nests it. Upright (all zero) this is the fixed model exactly;
a 0.52 rad waist tilt moves G at the arms by up to 3.3 N m, which an upright assumption would miss.
LowState_'s imu_state is read as the pelvis's orientation (Unitree's G1 deploy code reads it so; the
torso IMU is another topic): verify against the robot's SDK release before deploying.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from emopose.robot.feedforward import GravityModel

# (waist yaw, roll, pitch), (imu roll, pitch, yaw) in rad, or None before the first state
Orientation = Callable[[], tuple[np.ndarray, np.ndarray] | None]


def _rot(axis: int, angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    r = np.eye(3)
    r[i, i], r[i, j], r[j, i], r[j, j] = c, -s, s, c
    return r


def torso_rotation(waist: np.ndarray, rpy: np.ndarray) -> np.ndarray:
    """The torso's orientation in the world, up to yaw, from the waist joints and the pelvis IMU."""
    yaw, roll, pitch = waist
    return _rot(1, rpy[1]) @ _rot(0, rpy[0]) @ _rot(2, yaw) @ _rot(0, roll) @ _rot(1, pitch)


class TorsoGravity:
    """G(q) of the 14 arm joints with the torso where the robot measures it (upright before any state)."""

    def __init__(self, model: GravityModel, orientation: Orientation) -> None:
        self._model, self._orientation = model, orientation
        # The world's gravity in the upright model's frame (its size from the model, which this turns)
        self._gravity = np.array([0.0, 0.0, -np.linalg.norm(model.model.opt.gravity)])

    def __call__(self, q: np.ndarray) -> np.ndarray:
        measured = self._orientation()
        rotation = np.eye(3) if measured is None else torso_rotation(*measured)
        self._model.model.opt.gravity[:] = rotation.T @ self._gravity
        return self._model(q)
