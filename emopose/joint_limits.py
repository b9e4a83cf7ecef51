"""The robot's joint limits and speed bounds, read from the library set's limits file, and the error every
library file raises (the limits file is the first one a library set loads)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

from emopose import NUM_JOINTS


class LibraryError(ValueError):
    """A library file or library configuration is invalid; the message says where and how to fix it."""


@dataclass(frozen=True)
class JointLimits:
    """Hard joint limits q-, q+ (rad) and speed bounds (rad/s), in the library's 14-joint order."""

    names: tuple[str, ...]
    lower: np.ndarray
    upper: np.ndarray
    max_velocity: np.ndarray
    # The tracking reserve (the limits file's `tracking_reserve`): commands are planned at most
    # speed_fraction of max_velocity and at least limit_margin inside lower/upper, because the arm under its
    # law overshoots what it is sent; the measured joints then stay inside the bounds themselves.
    speed_fraction: float = 1.0
    limit_margin: float = 0.0

    @classmethod
    def from_file(cls, path: str | Path) -> JointLimits:
        path = Path(path)
        try:
            raw = yaml.safe_load(path.read_text())
            names = tuple(raw["joints"])
            lower, upper = (np.asarray(raw[k], dtype=float) for k in ("lower", "upper"))
            velocity = np.broadcast_to(np.asarray(raw.get("max_velocity", 6.0), dtype=float), (NUM_JOINTS,))
            reserve = raw.get("tracking_reserve") or {}
            fraction = float(reserve.get("speed_fraction", 1.0))
            margin = float(reserve.get("limit_margin", 0.0))
        except (OSError, yaml.YAMLError, KeyError, TypeError, ValueError) as exc:
            raise LibraryError(
                f"{path}: cannot read joint limits ({exc!r}); need joints, lower, upper"
            ) from exc
        if not (len(names) == lower.size == upper.size == NUM_JOINTS):
            raise LibraryError(f"{path}: joints, lower and upper must each list {NUM_JOINTS} values")
        if np.any(lower >= upper):
            bad = [names[j] for j in np.flatnonzero(lower >= upper)]
            raise LibraryError(f"{path}: lower must be below upper for {bad}")
        if not (0.0 < fraction <= 1.0 and 0.0 <= margin < float(np.min(upper - lower)) / 2):
            raise LibraryError(f"{path}: tracking_reserve needs 0 < speed_fraction <= 1 and "
                               f"0 <= limit_margin < half the narrowest range; got {fraction}, {margin}")
        return cls(names, lower, upper, velocity.copy(), fraction, margin)

    def planning(self) -> JointLimits:
        """The bounds commands are planned in: the hard limits and speed bounds less the tracking reserve."""
        m = self.limit_margin
        velocity = self.max_velocity * self.speed_fraction
        return JointLimits(self.names, self.lower + m, self.upper - m, velocity)

    def target_bounds(self, margin: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """Where a gesture's target poses may lie: `margin` inside the hard limits (the paper's delta), and no
        closer than the tracking reserve's margin, where commands are clipped (a target beyond it would
        never be reached, its stroke never arrive)."""
        m = max(margin, self.limit_margin)
        return self.lower + m, self.upper - m

    def keep_inside(self, q: np.ndarray, margin: float = 0.0) -> np.ndarray:
        """Pi_j of Eq. intensity: clip target poses into target_bounds(margin); (14,) or (T, 14)."""
        return np.clip(q, *self.target_bounds(margin))

    def project(self, q: np.ndarray, margin: float = 0.0) -> np.ndarray:
        """Pi_j: clip into [q- + margin, q+ - margin] joint-wise; works on (14,) or (T, 14)."""
        return np.clip(q, self.lower + margin, self.upper - margin)

    def _outside(self, q: np.ndarray, margin: float) -> np.ndarray:
        """(T, 14) mask: where q leaves [q- + margin, q+ - margin]."""
        return (q < self.lower + margin) | (q > self.upper - margin)

    def violations(self, q: np.ndarray, margin: float = 0.0) -> list[str]:
        """Names of joints that leave [q- + margin, q+ - margin] anywhere in q ((14,) or (T, 14))."""
        bad = np.any(self._outside(np.atleast_2d(q), margin), axis=0)
        return [self.names[j] for j in np.flatnonzero(bad)]

    def violation_details(self, q: np.ndarray, margin: float = 0.0) -> list[str]:
        """One line per offending joint of (K, 14) keyframes: its worst keyframe, value and allowed range."""
        q = np.atleast_2d(q)
        low, high = self.lower + margin, self.upper - margin
        excess = np.maximum(low - q, q - high)  # > 0 outside
        out = []
        for j in np.flatnonzero(np.any(self._outside(q, margin), axis=0)):
            k = int(np.argmax(excess[:, j]))
            out.append(f"{self.names[j]} = {q[k, j]:.3f} rad in keyframe {k} "
                       f"(allowed {low[j]:.3f}..{high[j]:.3f})")
        return out
