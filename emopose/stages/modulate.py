"""Modulate: intensity changes only the interior excursion about the first keyframe (Eq. intensity).

q~_kj = q_kj                                    if i = 3 or k in {0, K-1}
      = Pi_j(q_0j + a_i (q_kj - q_0j))          otherwise,
with a = (0.4, 0.6, 1.0, 1.3, 1.6) for i = 1..5 and Pi_j the clip into [q-_j + delta, q+_j - delta].
Duration is invariant.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from emopose.library import JointLimits
from emopose.stages.resolve import ResolvedGesture

INTENSITY_GAINS = (0.4, 0.6, 1.0, 1.3, 1.6)
LIMIT_MARGIN = 0.02


@dataclass(frozen=True)
class ModulatedGesture:
    """A resolved gesture with its intensity-scaled (K, 14) keyframes and (unchanged) duration in s."""

    resolved: ResolvedGesture
    keyframes: np.ndarray
    duration: float

    @property
    def name(self) -> str:
        return self.resolved.entry.name

    @property
    def intensity(self) -> int:
        return self.resolved.record.intensity


def modulate_keyframes(q: np.ndarray, intensity: int, limits: JointLimits,
                       gains: tuple[float, ...] = INTENSITY_GAINS, margin: float = LIMIT_MARGIN) -> np.ndarray:
    """Apply Eq. intensity to (K, 14) keyframes; returns a new array (level 3 returns an exact copy)."""
    out = np.array(q, dtype=float)
    if intensity == 3 or len(out) < 3:
        return out
    interior = out[1:-1]
    out[1:-1] = limits.project(out[0] + gains[intensity - 1] * (interior - out[0]), margin)
    return out


@dataclass
class Modulate:
    """Stage: resolved -> modulated."""

    gains: tuple[float, ...] = INTENSITY_GAINS
    margin: float = LIMIT_MARGIN
    name = "modulate"
    reads = ("resolved",)
    writes = "modulated"

    def __post_init__(self) -> None:
        self.gains = tuple(float(g) for g in self.gains)
        if len(self.gains) != 5 or self.gains[2] != 1.0:
            raise ValueError(f"pipeline.modulate.gains needs 5 values with level 3 = 1.0, got {self.gains}")

    def __call__(self, turn, ctx) -> list[ModulatedGesture]:
        return [self.modulate(r, ctx.library.limits) for r in turn.resolved]

    def modulate(self, resolved: ResolvedGesture, limits: JointLimits) -> ModulatedGesture:
        entry = resolved.entry
        q = modulate_keyframes(entry.q, resolved.record.intensity, limits, self.gains, self.margin)
        return ModulatedGesture(resolved, q, entry.default_duration)
