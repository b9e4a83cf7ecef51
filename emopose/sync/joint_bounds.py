"""How far a measured joint stream goes past the hard limits and the speed bounds (issue 28 item 6).

The timeline keeps the commands inside both; the motors under their law (feed-forward, gains, gravity)
may still overshoot. Speeds are finite differences between consecutive samples (one control period
apart), so a peak shorter than a period reads lower: the ratio is a lower bound on the true peak.
"""

from __future__ import annotations

import numpy as np

from emopose.joint_limits import JointLimits

SPEED_RATIO_BOUND = 1.05  # the live target: never above 1.05x the speed bound


def joint_bounds(times: np.ndarray, q: np.ndarray, limits: JointLimits) -> dict:
    """times (T,), q (T, 14) -> the worst excursion past the limits and the worst speed ratio."""
    q = np.asarray(q, dtype=float).reshape(-1, len(limits.names))
    outside = np.maximum(q - limits.upper, limits.lower - q).clip(min=0.0)
    dt = np.diff(np.asarray(times, dtype=float))
    keep = dt > 1e-9  # repeated stamps (a restart) carry no speed
    ratio = np.abs(np.diff(q, axis=0)[keep]) / dt[keep, None] / limits.max_velocity
    worst_joint = int(np.argmax(ratio.max(axis=0))) if ratio.size else 0
    return {"samples": int(len(q)),
            "beyond_limits_max_rad": float(outside.max(initial=0.0)),
            "samples_beyond_limits": int(np.any(outside > 0, axis=1).sum()),
            "speed_ratio_max": float(ratio.max(initial=0.0)),
            "speed_ratio_worst_joint": limits.names[worst_joint],
            "samples_above_speed_bound": int(np.any(ratio > SPEED_RATIO_BOUND, axis=1).sum())}
