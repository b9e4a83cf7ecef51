"""Executed means executed: the stroke as the measured joints reach it, not as the command stream does.

With a backend that measures its joints (MuJoCo's simulated state, the G1's LowState), the sequencer
reports the command stream's arrival at the stroke keyframe as STROKE_COMMANDED and hands the
gesture to a StrokeWatch; the control loop shows it every measured pose, and the STROKE event comes
when the measured arm is within the tolerance of that keyframe (the motors trail the command by their
tracking lag). An arm that does not get there within `expire_s` of the command's arrival (blocked,
stopped, a tolerance too tight for the law) gets its STROKE event then, with a detail starting "not
reached" that gives its closest approach, so no stroke goes unreported, none is reported as reached
that was not, and event times stay in order.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from emopose import STROKE_TOLERANCE
from emopose.execution.gesture_command import GestureCommand


@dataclass
class _Awaited:
    command: GestureCommand
    keyframe: np.ndarray
    commanded_t: float
    closest: float = math.inf
    closest_t: float = math.nan


@dataclass(frozen=True)
class MeasuredStroke:
    command: GestureCommand
    t: float
    detail: str  # "" when reached within the tolerance, else the closest approach


class StrokeWatch:
    def __init__(self, tolerance: float = STROKE_TOLERANCE, expire_s: float = 0.5) -> None:
        self.tolerance, self.expire_s = tolerance, expire_s
        self.measuring = False  # the control loop turns it on when its backend measures its joints
        self._awaited: list[_Awaited] = []

    def expect(self, command: GestureCommand, t: float) -> None:
        """The command stream reached command's stroke keyframe at t."""
        self._awaited.append(_Awaited(command, np.asarray(command.keyframes[command.stroke[0]]), t))

    def observe(self, t: float, q: np.ndarray) -> list[MeasuredStroke]:
        """The strokes this measured pose (at stream-clock time t) completes."""
        done, waiting = [], []
        for awaited in self._awaited:
            distance = float(np.max(np.abs(np.asarray(q) - awaited.keyframe)))
            if distance < awaited.closest:
                awaited.closest, awaited.closest_t = distance, t
            if distance <= self.tolerance:
                done.append(MeasuredStroke(awaited.command, t, ""))
            elif t - awaited.commanded_t >= self.expire_s:
                detail = (f"not reached: closest {awaited.closest:.3f} rad (tolerance {self.tolerance:g}) "
                          f"{(awaited.closest_t - awaited.commanded_t) * 1e3:+.0f} ms from the command's")
                done.append(MeasuredStroke(awaited.command, t, detail))
            else:
                waiting.append(awaited)
        self._awaited = waiting
        return done

    def clear(self) -> None:
        self._awaited = []
