"""Modulate: intensity changes only the interior excursion about the first keyframe (Eq. intensity).

q~_kj = q_kj                                    if i = 3 or k in {0, K-1}
      = Pi_j(q_0j + a_i (q_kj - q_0j))          otherwise,
with a = (0.4, 0.6, 1.0, 1.3, 1.6) for i = 1..5 and Pi_j the clip into [q-_j + delta, q+_j - delta].
Duration is invariant. Beyond the paper: where the limits file's tracking reserve keeps commands further
inside than delta, Pi_j clips there (JointLimits.keep_inside), so the stroke pose is one the arm is sent to.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from emopose.joint_limits import JointLimits
from emopose.turn.model import ModulatedGesture, ResolvedGesture, Turn

INTENSITY_GAINS = (0.4, 0.6, 1.0, 1.3, 1.6)
LIMIT_MARGIN = 0.02


def modulate_keyframes(q: np.ndarray, intensity: int, limits: JointLimits,
                       gains: tuple[float, ...] = INTENSITY_GAINS,
                       margin: float = LIMIT_MARGIN) -> np.ndarray:
    """Apply Eq. intensity to (K, 14) keyframes; returns a new array (level 3 returns an exact copy)."""
    out = np.array(q, dtype=float)
    if intensity == 3 or len(out) < 3:
        return out
    out[1:-1] = limits.keep_inside(scale_excursion(out, gains[intensity - 1])[1:-1], margin)
    return out


def scale_excursion(q: np.ndarray, gain: float) -> np.ndarray:
    """Eq. intensity's core: interior keyframes moved `gain` times as far from the first one (first and
    last unchanged; fewer than three keyframes have no interior)."""
    out = np.array(q, dtype=float)
    if len(out) >= 3:
        out[1:-1] = out[0] + gain * (out[1:-1] - out[0])
    return out


@dataclass
class Modulate:
    """Stage: resolved -> modulated, inside the robot's joint limits."""

    limits: JointLimits = field(repr=False)
    gains: tuple[float, ...] = INTENSITY_GAINS
    margin: float = LIMIT_MARGIN
    name = "modulate"
    reads = ("resolved",)
    writes = ("modulated",)

    def __post_init__(self) -> None:
        self.gains = tuple(float(g) for g in self.gains)
        if len(self.gains) != 5 or self.gains[2] != 1.0:
            raise ValueError(f"pipeline.modulate.gains needs 5 values with level 3 = 1.0, got {self.gains}")

    def __call__(self, turn: Turn) -> list[ModulatedGesture]:
        return [self.modulate(r) for r in turn.resolved]

    def keyframes(self, q: np.ndarray, intensity: int) -> np.ndarray:
        """Eq. intensity with this stage's gains, margin and limits."""
        return modulate_keyframes(q, intensity, self.limits, self.gains, self.margin)

    def modulate(self, resolved: ResolvedGesture) -> ModulatedGesture:
        entry = resolved.entry
        q = self.keyframes(entry.q, resolved.record.intensity)
        return ModulatedGesture(resolved, q, entry.default_duration)
