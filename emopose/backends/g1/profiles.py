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
    return ramp_ticks(start, end, n_steps(duration_s, dt))


def ramp_ticks(start: float, end: float, n: int) -> np.ndarray:
    """ramp() over exactly n >= 1 ticks."""
    out = start + (end - start) * smooth(np.arange(1, n + 1) / n)
    out[-1] = end
    return out


def blend_ticks(q_from: np.ndarray, q_to: np.ndarray, n: int) -> np.ndarray:
    """(n, 14) poses moving smoothly from q_from to q_to over n ticks; the last row is exactly q_to."""
    s = smooth(np.arange(1, n + 1) / n)[:, None]
    out = q_from[None, :] + (q_to - q_from)[None, :] * s
    out[-1] = q_to
    return out


def max_step(duration_s: float, dt: float, span: float = 1.0) -> float:
    """Upper bound of one tick's change in a ramp() of the given span (for tests and logs)."""
    n = n_steps(duration_s, dt)
    return abs(span) * math.sin(math.pi / (2 * n)) if n > 1 else abs(span)
