"""Commanded vs. simulated joint streams: alignment, N-point resampling and the sim MAE.

The streams are captured by emopose.backends.stream_tap.StreamTap.

Alignment (the one thing to be honest about): the MuJoCo backend holds command n as the servo
setpoint for the control period [t_n, t_n + dt] and stamps the simulated pose at the end of that
period t_n + dt (/joints/sim). We pair command n with the state after tick n's physics ("tick"
alignment: how close the servo got to each target by the end of its period). A strict wall-clock
pairing compares the same state with command n + 1, issued at t_n + dt ("time" alignment); it adds
one period of lag (~|dq| dt) and is reported beside it.

Paper Eq. sim-MAE: E = 1/(D N J) sum_d sum_n sum_j |q_sim - q_target| over D trials, each trial's
pair of streams linearly resampled to N points.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def resample(stream: np.ndarray, points: int = 100) -> np.ndarray:
    """Linearly resample a (T, J) stream, uniform in time, to (points, J) spanning the same interval."""
    stream = np.asarray(stream, dtype=float)
    if len(stream) == 1:
        return np.repeat(stream, points, axis=0)
    x = np.linspace(0.0, len(stream) - 1, points)
    i0 = np.minimum(x.astype(int), len(stream) - 2)
    frac = (x - i0)[:, None]
    return stream[i0] + frac * (stream[i0 + 1] - stream[i0])


@dataclass(frozen=True)
class TrackingError:
    """Per-trial resampled absolute errors (N, J) under both alignments, plus the raw peak error."""

    tick: np.ndarray
    time: np.ndarray
    max_abs: float

    @property
    def mae(self) -> float:
        return float(self.tick.mean())

    @property
    def mae_time_aligned(self) -> float:
        return float(self.time.mean())


def tracking_error(commands: np.ndarray, states: np.ndarray, points: int = 100) -> TrackingError:
    """Errors of one trial's paired streams (commands[n] with the state after tick n's physics)."""
    commands, states = np.asarray(commands, float), np.asarray(states, float)
    tick = np.abs(resample(states, points) - resample(commands, points))
    # Time alignment: the state stamped t_n + dt against the command issued at t_n + dt.
    later = commands[1:] if len(commands) > 1 else commands
    earlier = states[:-1] if len(states) > 1 else states
    time = np.abs(resample(earlier, points) - resample(later, points))
    return TrackingError(tick, time, float(np.max(np.abs(states - commands))))


def sim_mae(errors: list[TrackingError], aligned: str = "tick") -> float:
    """Eq. sim-MAE over D trials (every trial weighs N x J, whatever its duration)."""
    if not errors:
        return float("nan")
    stack = np.stack([e.tick if aligned == "tick" else e.time for e in errors])
    return float(stack.mean())


def latency_ms(seconds: list[float] | tuple[float, ...]) -> dict:
    """mean / p95 / max in milliseconds of a list of durations in seconds."""
    ms = np.asarray(seconds, dtype=float) * 1e3
    if ms.size == 0:
        return {"mean": None, "p95": None, "max": None, "n": 0}
    return {"mean": float(ms.mean()), "p95": float(np.percentile(ms, 95)), "max": float(ms.max()),
            "n": int(ms.size)}
