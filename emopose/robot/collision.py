"""Self-collision heuristic for the G1 arms: link capsules vs. the torso, the head, the other arm.

Body models, in the torso_link frame (g1.md's shoulder and head figures; the torso box equals the
chest, abdomen and pelvis of the project's MJCF, emopose/robot/assets/g1_upper_body.xml, and the arm
capsules enclose its arm geoms, so with the 1 cm margin a clean verdict means no contact there):
  arm links  capsules: upper arm (shoulder_roll origin -> elbow, r 0.04), forearm (elbow ->
             wrist_yaw origin, r 0.032), hand (0.0415 .. 0.1415 m along wrist_yaw's +x, r 0.035)
  torso      a box from the pelvis to the neck: |x| <= 0.075, |y| <= 0.09, -0.12 <= z <= 0.285
  head       a short vertical capsule, 0.36 .. 0.43 m above the waist joint (g1.md: 0.40-0.45 m),
             r 0.09, so that it also covers the chin and neck
Within one arm only the hand is checked against the upper arm (the joint limits keep the other
links apart); against the torso the upper arm counts from the shoulder_yaw link down, because
above it the arm is mounted on the torso.
Capsule pairs use an exact segment-segment distance; a capsule against the box uses a lower bound
of the segment-box distance (never above the truth, typically within a millimetre of it). Every
pair over every sample is computed in one vectorised pass, in float32.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from emopose.robot import kinematics as K
from emopose.robot.g1_spec import ARM_DOF
from emopose.robot.kinematics import mirrored_chain, unmirror

ARM_LINKS = ("upper_arm", "forearm", "hand")
ARM_RADII = (0.04, 0.032, K.HAND_RADIUS)
TORSO_BOX = ((-0.075, -0.09, -0.12), (0.075, 0.09, 0.285))  # lower and upper corner
HEAD = ((0.01, 0.0, 0.36), (0.01, 0.0, 0.43), 0.09)  # capsule: start, end, radius
# For drawing (emopose.web.stick_figure): the torso box's vertical centre line and half-width.
FIXED_BODIES = {"torso": ((0.0, 0.0, -0.12), (0.0, 0.0, 0.285), 0.09), "head": HEAD}
ARM_BODIES = tuple(f"{side}_{link}" for side in ("left", "right") for link in ARM_LINKS)
BODY_NAMES = (*ARM_BODIES, "torso", "head")
TORSO, HEAD_INDEX = 6, 7

# Checked pairs, in the column order of `clearances`: every arm link vs. the torso box, then the
# capsule pairs: every arm link vs. the head, every left link vs. every right link, and each hand
# vs. its own upper arm.
_CAPSULE_PAIRS = [(a, HEAD_INDEX) for a in range(6)]
_CAPSULE_PAIRS += [(a, b) for a in range(3) for b in range(3, 6)] + [(2, 0), (5, 3)]
PAIR_A = np.array([*range(6), *(a for a, _ in _CAPSULE_PAIRS)])
PAIR_B = np.array([TORSO] * 6 + [b for _, b in _CAPSULE_PAIRS])
_RADII = np.array(ARM_RADII * 2 + (0.0, HEAD[2]), np.float32)
_CAP_A, _CAP_B = PAIR_A[6:], PAIR_B[6:]
_CAP_RADII = (_RADII[_CAP_A] + _RADII[_CAP_B])[:, None]
_CAP_ROWS_B = np.where(_CAP_B == HEAD_INDEX, 8, _CAP_B)  # row of the head in `clearances`
_BOX_ROWS = [6, 1, 2, 7, 4, 5]  # against the torso the upper arms count from the yaw link down
_ARM_RADII = _RADII[:6, None]
_BOX_LO, _BOX_HI = (np.array(c, np.float32)[:, None, None, None] for c in TORSO_BOX)
_HEAD_START = np.array(HEAD[0], np.float32)[:, None, None]
_HEAD_DIR = np.array(HEAD[1], np.float32)[:, None, None] - _HEAD_START
_HEAD_LENGTH2 = float((_HEAD_DIR**2).sum())
_BOX_SAMPLES = 7  # points per arm segment for the box bound
_EPS = 1e-20  # squared length given to a zero-length segment (a sphere)


def _closest(p1, d1, a, p2, d2, e):
    """Segment distances on component planes (3, ...); a, e = squared lengths > 0 (Ericson 5.1.9).

    Branch-free variant: s from the unconstrained optimum, t from s, then s again from the clamped
    t. The last step is Ericson's case split when t was clamped and harmless otherwise (optimising
    s for a fixed t cannot leave the minimum); it avoids np.where, which is slow. For parallel
    segments the first s lands on an end point and the two projections still find the minimum.
    """
    r = p1 - p2
    b, c, f = (d1 * d2).sum(0), (d1 * r).sum(0), (d2 * r).sum(0)
    s = np.clip((b * f - c * e) / np.maximum(a * e - b * b, _EPS), 0.0, 1.0)
    t = np.clip((b * s + f) / e, 0.0, 1.0)
    s = np.clip((b * t - c) / a, 0.0, 1.0)
    gap = r + s * d1 - t * d2
    return np.sqrt((gap * gap).sum(0))


def _box_distance_bound(start: np.ndarray, direction: np.ndarray, length2: np.ndarray) -> np.ndarray:
    """Lower bound (S, T) of the distance from segments (3, S, T) to the torso box.

    The distance f to a convex set is convex along a segment. Sampled at n points, f on each
    interval lies above the lines through its neighbouring samples (at the segment's ends, above
    the slope bound |f'| <= length); the minimum of the upper envelope of those two lines is the
    bound. It is exact wherever f is linear or flat (an arm alongside the torso) and conservative
    only near a kink, by less than the sample spacing.
    """
    n = _BOX_SAMPLES
    u = np.linspace(0.0, 1.0, n, dtype=start.dtype)[:, None]
    points = start[:, :, None, :] + u * direction[:, :, None, :]  # (3, S, n, T)
    outside = points - np.clip(points, _BOX_LO, _BOX_HI)
    f = np.sqrt((outside * outside).sum(0))  # (S, n, T)
    slope = np.diff(f, axis=1)
    step = (np.sqrt(length2) / (n - 1))[:, None, :]
    left = np.concatenate([-step, slope[:, :-1]], axis=1)  # slope of the line through k-1, k
    right = np.concatenate([slope[:, 1:], step], axis=1)  # slope of the line through k+1, k+2
    f0, f1 = f[:, :-1], f[:, 1:]
    x = np.clip((f1 - right - f0) / np.minimum(left - right, -1e-12), 0.0, 1.0)  # where they cross
    at_x = np.maximum(f0 + left * x, f1 - right * (1.0 - x))
    # If f is linear there the lines coincide, x is arbitrary and the minimum is an end sample.
    return np.maximum(np.minimum(at_x, np.minimum(f0, f1)).min(axis=1), 0.0)


def segment_distance(p1: np.ndarray, q1: np.ndarray, p2: np.ndarray, q2: np.ndarray) -> np.ndarray:
    """Closest distance between segments p1-q1 and p2-q2 (xyz on the last axis), elementwise."""
    p1, q1, p2, q2 = (np.moveaxis(np.asarray(x, dtype=float), -1, 0) for x in (p1, q1, p2, q2))
    d1, d2 = q1 - p1, q2 - p2
    a, e = np.maximum((d1 * d1).sum(0), _EPS), np.maximum((d2 * d2).sum(0), _EPS)
    return _closest(p1, d1, a, p2, d2, e)


def _segments(samples: np.ndarray, dtype: type) -> tuple[np.ndarray, np.ndarray]:
    """Starts and directions (3, 8, T): ARM_BODIES' capsules, then the upper arms below yaw."""
    qa = np.asarray(samples, dtype=float).reshape(-1, 2, ARM_DOF)
    n = qa.shape[0]
    cols, pos = mirrored_chain(qa, dtype)
    hand_x, wrist = cols[6][0], pos[6]
    hand = wrist + dtype(K.HAND_ORIGIN) * hand_x
    start = np.stack([pos[1], pos[3], hand, pos[2]], axis=1)  # (3, link, 2T)
    end = np.stack([pos[3], wrist, wrist + dtype(K.HAND_END) * hand_x, pos[3]], axis=1)
    start, direction = start.reshape(3, 4, 2, n), (end - start).reshape(3, 4, 2, n)
    order = [0, 1, 2, 4, 5, 6, 3, 7]  # (side, link) rows: left 0-2, right 0-2, left 3, right 3
    start = unmirror(start.transpose(0, 2, 1, 3).copy(), points=True).reshape(3, 8, n)[:, order]
    direction = unmirror(direction.transpose(0, 2, 1, 3).copy(), points=False).reshape(3, 8, n)
    return start, direction[:, order]


@dataclass(frozen=True)
class CollisionReport:
    """Verdict on a batch of samples; `min_clearance_m` is the smallest surface gap of any pair."""

    ok: bool
    reason: str | None
    min_clearance_m: float


class SelfCollisionChecker:
    """Rejects joint samples whose bodies come closer than `clearance` metres."""

    def __init__(self, clearance: float = 0.01) -> None:
        self.clearance = float(clearance)

    def clearances(self, samples: np.ndarray) -> np.ndarray:
        """Surface gaps (T, P) in metres of the pairs (PAIR_A[p], PAIR_B[p]); negative = overlap."""
        start, direction = _segments(np.atleast_2d(samples), np.float32)  # (3, 8, T)
        length2 = np.maximum((direction * direction).sum(0), _EPS)
        rows = _BOX_ROWS
        torso = _box_distance_bound(start[:, rows], direction[:, rows], length2[rows]) - _ARM_RADII
        head = (3, 1, start.shape[2])
        start = np.concatenate([start, np.broadcast_to(_HEAD_START, head)], axis=1)  # head: row 8
        direction = np.concatenate([direction, np.broadcast_to(_HEAD_DIR, head)], axis=1)
        length2 = np.concatenate([length2, np.full((1, head[2]), _HEAD_LENGTH2, np.float32)])
        a, b = _CAP_A, _CAP_ROWS_B
        dist = _closest(start[:, a], direction[:, a], length2[a], start[:, b], direction[:, b], length2[b])
        return np.concatenate([torso, dist - _CAP_RADII]).T

    def check(self, samples: np.ndarray) -> CollisionReport:
        """Check (T, 14) or (14,) joint samples; a reason names the worst pair and its sample."""
        gaps = self.clearances(samples)
        t, p = np.unravel_index(int(np.argmin(gaps)), gaps.shape)
        worst = float(gaps[t, p])
        if worst >= self.clearance:
            return CollisionReport(True, None, worst)
        a, b = BODY_NAMES[PAIR_A[p]], BODY_NAMES[PAIR_B[p]]
        reason = f"{a} vs {b} at sample {t}: clearance {worst:.3f} m < {self.clearance:.3f} m"
        return CollisionReport(False, reason, worst)
