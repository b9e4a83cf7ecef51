"""planner=chance: a uniformly random class per request, from a seeded generator.

The generator is created once per planner, so a run is reproducible for a given seed and repeated
passes within a run draw fresh labels. Expected top-1 accuracy on a balanced suite is 1/8 = 12.5%.
"""

from __future__ import annotations

import numpy as np

from emopose import CLASSES
from emopose.planners.base import PlannerOutput, PlanRequest, timed
from emopose.planners.baselines.lexical import single_record_output


class ChancePlanner:
    """Uniform chance baseline (paper Table semantic)."""

    name = "chance"
    sampled = False  # seeded: one pass is reproducible; pass passes=5 to see its spread

    def __init__(self, seed: int = 0) -> None:
        self.seed = seed
        self.rng = np.random.default_rng(seed)

    def plan(self, request: PlanRequest) -> PlannerOutput:
        with timed() as clock:
            cls = CLASSES[int(self.rng.integers(len(CLASSES)))]
        return single_record_output(request, cls, 1.0 / len(CLASSES), clock.elapsed)
