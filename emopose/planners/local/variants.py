"""The local planner's variant choice: the motion of the act's class whose description fits its words
(the score: planners/local/variant_score.py), and with it the act's class.

A motion file's `examples:` (utterances it fits) are read like its description, and a motion scores as
its best-fitting text: evidence for a new motion's uses without retraining (planners/local/catalogue.py).
An example is also a labelled utterance: how unlikely the class head finds the motion's class on it is
how far the head underrates that motion's uses, so an act the example fits best gets that much back.

The class is chosen with the motion (VariantChooser.choose): a motion of another class that fits the act
better than its own class's best can move it, by log p(class) + w * (the score margin); w is larger for a
motion the training data never annotated, whose uses the class head cannot know. A motion whose
best-fitting text is one of its examples adds -log p(its class | that example) to log p(class) where it
fits the act better than the act's own class's motions.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from emopose import CLASSES
from emopose.planners.local.variant_score import Compared, Features, Weights, projected, scores, word_presence


@dataclass(frozen=True)
class ClassMove:
    """How far a motion that fits an act better than its class's own motions may move the act's class
    (conf/planner/local.yaml)."""

    annotated: float  # toward a motion the training data annotates: the class head has read acts about it
    new: float  # toward one it never saw: the motion's description is the only evidence for its uses


class _Library(NamedTuple):
    """The live library as the choice reads it, for one library version."""

    version: int
    names: list[str]  # the selectable motions
    classes: np.ndarray  # (M,) each motion's class index
    is_annotated: np.ndarray  # (M,) whether the training data annotates it
    texts: Compared | None  # every motion's texts (its description, then its examples)
    owner: np.ndarray  # (T,) the motion each text belongs to
    underrated: np.ndarray  # (T,) -log p(owner's class | text) for an example, 0 for a description


class VariantChooser:
    """Inference: an act's class and motion. The descriptions are read and projected once per library
    version. describe(texts) -> their Features; annotated: the motions the training data annotates;
    read_classes(texts) -> (N, classes) the class head's log-probabilities of whole texts (None: a motion's
    examples count by their fit alone)."""

    def __init__(self, projections, describe: Callable[[list[str]], Features], weights: Weights,
                 annotated: frozenset[str],
                 read_classes: Callable[[list[str]], np.ndarray] | None = None) -> None:
        self.projections, self.describe, self.weights = projections, describe, weights
        self.annotated, self.read_classes = annotated, read_classes
        none = np.zeros(0, dtype=int)
        self._cached = _Library(-1, [], none, none.astype(bool), None, none, none.astype(float))

    def _underrated(self, entries: dict[str, tuple[str, tuple[str, ...]]]) -> np.ndarray:
        """Per text of the catalogue: -log p(its motion's class) as the class head reads it for an example
        utterance, 0 for a description (or without read_classes)."""
        is_example = np.array([k > 0 for _, texts in entries.values() for k in range(len(texts))], dtype=bool)
        examples = [(CLASSES.index(cls), text) for cls, texts in entries.values() for text in texts[1:]]
        underrated = np.zeros(len(is_example))
        if self.read_classes is not None and examples:
            classes, texts = zip(*examples, strict=True)
            underrated[is_example] = -self.read_classes(list(texts))[np.arange(len(texts)), list(classes)]
        return underrated

    def _library(self, catalogue, version: int) -> _Library:
        """The live library, read again when its version changes."""
        import torch

        cached = self._cached  # one read: another thread may replace it
        if cached.version != version:
            entries = catalogue()
            texts = [text for _, evidence in entries.values() for text in evidence]
            with torch.inference_mode():
                described = projected(self.projections, self.describe(texts))
            cached = self._cached = _Library(
                version, list(entries), np.array([CLASSES.index(c) for c, _ in entries.values()], dtype=int),
                np.array([name in self.annotated for name in entries], dtype=bool),
                described._replace(words=word_presence(described.words)),
                np.repeat(np.arange(len(entries)), [len(evidence) for _, evidence in entries.values()]),
                self._underrated(entries))
        return cached

    def _fits(self, act: Features, library: _Library) -> tuple[np.ndarray, np.ndarray]:
        """Per motion: its score (its best-fitting text's: description or example) and its credit (what
        the class head underrates that text by, when it is an example)."""
        import torch

        row, credit = np.full(len(library.names), -np.inf), np.zeros(len(library.names))
        with torch.inference_mode():
            fits = scores(projected(self.projections, act), library.texts, self.weights)[0]
        np.maximum.at(row, library.owner, fits)
        best_text = fits >= row[library.owner]
        np.maximum.at(credit, library.owner[best_text], library.underrated[best_text])
        return row, credit

    def choose(self, catalogue: Callable[[], dict[str, tuple[str, tuple[str, ...]]]], version: int, cls: str,
               proba: np.ndarray, act: Features, move: ClassMove, excluded: frozenset[str] = frozenset(),
               barred: frozenset[str] = frozenset()) -> tuple[str, str | None]:
        """(class, motion) for an act the split model reads as cls with class probabilities proba.
        Within cls the best-scoring motion is chosen. Another class c moves the act when its best motion
        m fits by enough more: log proba[c] + w(m) * (score(m) - score of cls's best) > log proba[cls],
        each side with its motion's credit when that motion's best-fitting text is an example (m's only
        when m fits better).
        w(m) is move.annotated for a motion the training data annotates and move.new for one it never
        saw: the class head's probabilities already weigh what the data says of a known motion's uses,
        while for a new one (a "finger wag" added by file, for a scolding the model read as comforting)
        the fit is all there is. A weight of 0 never moves; nor does anything when cls has no motion.
        Classes in excluded (the neighbouring acts') are never moved to; motions in barred are never
        chosen (an added pointing motion aimed a way the act does not name: the planner's rule,
        planners/local/direction.py), a class whose motions all are has none. catalogue() -> the live
        library's selectable motions, name -> (class, (description text, *example utterances)), read
        again when the library's version changes; a motion scores as its best-fitting text. act: the
        act's Features (one row)."""
        library = self._library(catalogue, version)
        names, classes = library.names, library.classes
        own = CLASSES.index(cls)
        selectable = np.array([name not in barred for name in names], dtype=bool)
        members = np.flatnonzero((classes == own) & selectable)
        if not len(members):
            return cls, None
        row, credit = self._fits(act, library)
        own_best = members[int(np.argmax(row[members]))]
        chosen, best_total = own_best, np.log(proba[own] + 1e-12) + credit[own_best]
        weight = np.where(library.is_annotated, move.annotated, move.new)
        for other in sorted(set(classes[selectable].tolist()) - {own} - {CLASSES.index(c) for c in excluded}):
            members = np.flatnonzero((classes == other) & selectable)
            m = members[int(np.argmax(row[members]))]
            if not weight[m]:
                continue  # no weight, no move (the split may have chosen a less likely class for a reason)
            margin = row[m] - row[own_best]  # a credit counts only where the example fits better
            total = np.log(proba[other] + 1e-12) + credit[m] * (margin > 0) + weight[m] * margin
            if total > best_total:  # a tie keeps the split model's class
                chosen, best_total = m, total
        return CLASSES[classes[chosen]], names[chosen]
