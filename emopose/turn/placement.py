"""A gesture being placed on the timeline (emopose/turn/timeline.py), and whether the robot accepts its path.

`Placed` holds a gesture's anchors (keyframe 0 = its start pose) and their times while the timeline places
it; it stays mutable because a later gesture may cut it. `PathCheck` applies the sequencer's pre-dispatch
safety check to a placement's whole motion, built from the pose it starts at as the sequencer builds it at
dispatch. A motion can be refused at one intensity even from rest (self_hug at 4, cross_arms_x at 5 in the
G1 library), so every placement is checked, not only the co-articulation blends. The path is sampled
CHECK_OVERSAMPLING times as densely as the stream: the sequencer samples it at whatever phase its release
tick gives, and a clearance it would sample just under the bound must not pass here on a luckier phase.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from emopose.execution.trajectory import TrajectoryBuilder
from emopose.turn.model import Fit, GestureTiming

CHECK_OVERSAMPLING = 4


@dataclass
class Placed:
    name: str
    anchors: np.ndarray
    stroke: tuple[int, int]
    steps: np.ndarray  # nominal length (s) of each segment, anchors[i] -> anchors[i + 1]
    times: list[float]
    target: float
    arrival: float
    fit: Fit
    blend_in: bool
    scale: float
    cut: int = field(default=-1)

    def timing(self) -> GestureTiming:
        keep = len(self.times) if self.cut < 0 else self.cut + 1
        return GestureTiming(self.anchors[:keep], tuple(self.times[:keep]), self.stroke, self.target,
                             self.arrival, self.fit, self.blend_in, self.scale, cut=self.cut >= 0)


class PathCheck:
    def __init__(self, builder: TrajectoryBuilder, safety: Callable[[np.ndarray], str | None] | None) -> None:
        self.safety = safety
        # builder.limits are already the planning ones, so the dense builder plans within the same bounds
        self._dense = TrajectoryBuilder(builder.limits, builder.dt / CHECK_OVERSAMPLING, builder.increments)

    def refusal(self, placed: Placed, start_pose: np.ndarray) -> str:
        """Why the check refuses the placed motion from start_pose (a stack of origins: the last, where the
        arm is); "" if it passes, or there is no check."""
        if self.safety is None:
            return ""
        times = np.asarray(placed.times[1:]) - placed.times[0]
        start = np.atleast_2d(start_pose)[-1]
        motion = self._dense.build_timed(placed.anchors, times, start, placed.blend_in)
        return self.safety(motion.samples) or ""
