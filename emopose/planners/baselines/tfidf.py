"""planner=tfidf: TF-IDF cosine between the utterance and one written description per class.

Numpy only. The eight descriptions are the documents: term frequency is the raw count, inverse
document frequency the smoothed log((1 + N) / (1 + df)) + 1 (scikit-learn's default), rows are
L2-normalised, and the utterance is projected onto the descriptions' vocabulary. The class with the
highest cosine wins; an utterance sharing no term with any description gets neutral.
"""

from __future__ import annotations

from collections import Counter

import numpy as np

from emopose.planners.base import PlannerOutput, PlanRequest, timed
from emopose.planners.baselines.lexical import (
    best_class,
    load_class_descriptions,
    single_record_output,
    tokenize,
)


class TfidfIndex:
    """TF-IDF vectors of a fixed document set; `scores(text)` gives cosine similarity to each document."""

    def __init__(self, documents: list[str], drop_stop_words: bool = True) -> None:
        self.drop_stop_words = drop_stop_words
        counts = [Counter(tokenize(d, drop_stop_words)) for d in documents]
        self.vocabulary = {t: k for k, t in enumerate(sorted(set().union(*counts)))}
        tf = np.zeros((len(documents), len(self.vocabulary)))
        for row, count in enumerate(counts):
            for term, n in count.items():
                tf[row, self.vocabulary[term]] = n
        df = (tf > 0).sum(axis=0)
        self.idf = np.log((1 + len(documents)) / (1 + df)) + 1.0
        self.matrix = _l2_rows(tf * self.idf)

    def vector(self, text: str) -> np.ndarray:
        v = np.zeros(len(self.vocabulary))
        for term in tokenize(text, self.drop_stop_words):
            k = self.vocabulary.get(term)
            if k is not None:
                v[k] += 1.0
        return _l2_rows((v * self.idf)[None, :])[0]

    def scores(self, text: str) -> np.ndarray:
        return self.matrix @ self.vector(text)


def _l2_rows(m: np.ndarray) -> np.ndarray:
    norms = np.linalg.norm(m, axis=1, keepdims=True)
    return m / np.where(norms > 0, norms, 1.0)


class TfidfPlanner:
    """TF-IDF descriptions baseline (paper Table semantic); one record, deterministic."""

    name = "tfidf"
    sampled = False

    def __init__(self, descriptions: str, drop_stop_words: bool = True) -> None:
        self.classes_text = load_class_descriptions(descriptions)
        self.index = TfidfIndex(list(self.classes_text.values()), drop_stop_words)

    def plan(self, request: PlanRequest) -> PlannerOutput:
        with timed() as clock:
            cls, score = best_class(self.index.scores(request.utterance))
        return single_record_output(request, cls, score, clock.elapsed)
