"""planner=jaccard: token-set Jaccard similarity between the utterance and each class description.

J(U, D_c) = |U & D_c| / |U | D_c| over lowercase word sets (function words dropped by default). The
highest J wins (ties: earlier class in the paper's order); no shared token at all gives neutral.
"""

from __future__ import annotations

import numpy as np

from emopose import CLASSES
from emopose.planners.base import PlannerOutput, PlanRequest, timed
from emopose.planners.baselines.lexical import (
    best_class,
    load_class_descriptions,
    single_record_output,
    tokenize,
)


def jaccard(a: set[str], b: set[str]) -> float:
    union = a | b
    return len(a & b) / len(union) if union else 0.0


class JaccardPlanner:
    """Jaccard descriptions baseline (paper Table semantic); one record, deterministic."""

    name = "jaccard"
    sampled = False

    def __init__(self, descriptions: str, drop_stop_words: bool = True) -> None:
        self.drop_stop_words = drop_stop_words
        texts = load_class_descriptions(descriptions)
        self.class_tokens = [set(tokenize(texts[c], drop_stop_words)) for c in CLASSES]

    def scores(self, text: str) -> np.ndarray:
        tokens = set(tokenize(text, self.drop_stop_words))
        return np.array([jaccard(tokens, d) for d in self.class_tokens])

    def plan(self, request: PlanRequest) -> PlannerOutput:
        with timed() as clock:
            cls, score = best_class(self.scores(request.utterance))
        return single_record_output(request, cls, score, clock.elapsed)
