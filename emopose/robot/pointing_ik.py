"""Aim a hand at a point: damped least squares on one 7-DoF arm, inside its joint limits.

The pointing axis is the hand's +x (the wrist_yaw link's x, along which the rubber hand extends);
the ray starts at the hand's base (HAND_ORIGIN along that axis). The task drives the unit error
e = u - d to zero, d the axis and u the unit direction from the hand base to the target:
    de/dq = -(I - u u^T) J_p / r  -  [a_j x d]_j
J_p from kinematics.hand_jacobian, a_j the joints' world axes. The arm has five spare DoF: they are
spent pulling toward the seed (the library's pointing pose), so the aimed pose keeps its character,
with wrists weighted heavier so shoulder and elbow do the aiming, as a person's arm does.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from emopose.robot.g1_spec import ARM_DOF
from emopose.robot.kinematics import AXES, HAND_ORIGIN, hand_jacobian, link_frames
from emopose.scene.geometry import angle_between

JOINT_WEIGHTS = np.array([1.0, 1.0, 1.5, 1.2, 3.0, 4.0, 4.0])  # shoulder x3, elbow, wrist x3


@dataclass(frozen=True)
class AimResult:
    q: np.ndarray  # (14,) the seed with this arm's 7 joints replaced
    side: int  # 0 left, 1 right
    error_rad: float
    iterations: int
    converged: bool


def hand_ray(q: np.ndarray, side: int) -> tuple[np.ndarray, np.ndarray]:
    """Hand base point (3,) and unit pointing axis (3,) in the torso frame."""
    rot, pos = link_frames(np.asarray(q, float))
    axis = rot[side, -1, :, 0]
    return pos[side, -1] + HAND_ORIGIN * axis, axis


def pointing_error(q: np.ndarray, side: int, target: np.ndarray) -> float:
    """Angle (rad) between the hand's pointing axis and the direction from the hand to the target."""
    origin, axis = hand_ray(q, side)
    return angle_between(axis, np.asarray(target, float) - origin)


def _task(q: np.ndarray, side: int, target: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Error e (3,) and its Jacobian (3, 7) w.r.t. this arm's joints."""
    rot, pos = link_frames(q)
    axis = rot[side, -1, :, 0]
    origin = pos[side, -1] + HAND_ORIGIN * axis
    offset = target - origin
    r = max(float(np.linalg.norm(offset)), 1e-6)
    u = offset / r
    j_point = hand_jacobian(q, side, along_x=HAND_ORIGIN)  # (3, 7)
    joint_axes = np.stack([rot[side, j, :, a] for j, a in enumerate(AXES)])  # (7, 3)
    j_axis = np.cross(joint_axes, axis).T  # d(d)/dq_j = a_j x d
    j_dir = -(np.eye(3) - np.outer(u, u)) @ j_point / r
    return u - axis, j_dir - j_axis


def aim_arm(seed: np.ndarray, side: int, target: np.ndarray, lower: np.ndarray, upper: np.ndarray,
            tolerance: float = math.radians(0.3), max_iterations: int = 150, damping: float = 0.05,
            posture_gain: float = 0.2, max_step: float = 0.15) -> AimResult:
    """Move one arm of `seed` (14,) so its hand points at `target` (torso frame), within [lower, upper]."""
    q = np.clip(np.asarray(seed, float).copy(), lower, upper)
    target = np.asarray(target, float)
    arm = slice(side * ARM_DOF, (side + 1) * ARM_DOF)
    rest = q[arm].copy()
    w_inv = 1.0 / JOINT_WEIGHTS
    for iteration in range(1, max_iterations + 1):
        error, jac = _task(q, side, target)
        if float(np.linalg.norm(error)) < 2.0 * math.sin(tolerance / 2.0):  # chord of the angle
            return AimResult(q, side, pointing_error(q, side, target), iteration - 1, True)
        jw = jac * w_inv
        pinv = jw.T @ np.linalg.inv(jac @ jw.T + damping**2 * np.eye(3))  # weighted DLS inverse (7, 3)
        step = pinv @ (-error)
        null = np.eye(ARM_DOF) - pinv @ jac
        step += null @ (posture_gain * (rest - q[arm]))
        step *= min(1.0, max_step / max(float(np.abs(step).max()), 1e-12))
        proposed = q[arm] + step
        pinned = (proposed < lower[arm]) | (proposed > upper[arm])
        if pinned.any():  # a joint at its limit drops out of this step; the others take up the motion
            jw = jac * (w_inv * ~pinned)
            pinv = jw.T @ np.linalg.inv(jac @ jw.T + damping**2 * np.eye(3))
            step = pinv @ (-error)
            step *= min(1.0, max_step / max(float(np.abs(step).max()), 1e-12))
            proposed = q[arm] + step
        q[arm] = np.clip(proposed, lower[arm], upper[arm])
    error = pointing_error(q, side, target)
    return AimResult(q, side, error, max_iterations, error <= tolerance)
