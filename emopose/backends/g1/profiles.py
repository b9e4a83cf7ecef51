"""Sampled profiles for handing the arms over and back: weight ramps and pose blends.

All ramps use the half-cosine s(u) = (1 - cos(pi u)) / 2: it starts and ends with zero slope,
so neither the weight nor the target jumps at either end, and its largest per-tick step is
pi/2 * dt / T (about 0.031 for a 1 s ramp at 50 Hz; Unitree's example ramps linearly at 0.02).
"""

from __future__ import annotations

import math

import numpy as np


def n_steps(duration_s: float, dt: float) -> int:
    """Ticks needed to cover duration_s (at least one, so a zero duration still ends exactly)."""
    return max(1, math.ceil(duration_s / dt - 1e-9))


def smooth(u: np.ndarray | float) -> np.ndarray:
    u = np.clip(u, 0.0, 1.0)
    return 0.5 * (1.0 - np.cos(np.pi * u))


def ramp(start: float, end: float, duration_s: float, dt: float) -> np.ndarray:
    """Values after each tick going from start to end; the last element is exactly `end`."""
    n = n_steps(duration_s, dt)
    s = smooth(np.arange(1, n + 1) / n)
    out = start + (end - start) * s
    out[-1] = end
    return out


def blend(q_from: np.ndarray, q_to: np.ndarray, duration_s: float, dt: float) -> np.ndarray:
    """(n, 14) poses moving smoothly from q_from to q_to; the last row is exactly q_to."""
    n = n_steps(duration_s, dt)
    s = smooth(np.arange(1, n + 1) / n)[:, None]
    out = q_from[None, :] + (q_to - q_from)[None, :] * s
    out[-1] = q_to
    return out


def max_step(duration_s: float, dt: float, span: float = 1.0) -> float:
    """Upper bound of one tick's change in a ramp() of the given span (for tests and logs)."""
    n = n_steps(duration_s, dt)
    return abs(span) * math.sin(math.pi / (2 * n)) if n > 1 else abs(span)


def release_plan(
    q_from: np.ndarray,
    neutral: np.ndarray,
    weight: float,
    blend_s: float,
    ramp_down_s: float,
    dt: float,
) -> tuple[np.ndarray, np.ndarray]:
    """Ticks of the hand-back: blend the targets to neutral at the current weight, then ramp the
    weight to 0 holding neutral. The ramp takes weight * ramp_down_s (a full ramp from 1 takes
    ramp_down_s). Returns (poses (n, 14), weights (n,)); the last weight is exactly 0."""
    poses = blend(q_from, neutral, blend_s, dt) if blend_s > 0 else np.empty((0, len(q_from)))
    weights = np.full(len(poses), weight)
    if weight > 0:
        down = ramp(weight, 0.0, weight * ramp_down_s, dt)
        poses = np.vstack([poses, np.repeat(neutral[None, :], len(down), axis=0)])
        weights = np.concatenate([weights, down])
    return poses, weights
