"""The local planner's variant choice: the motion of the act's class whose description fits its words.

An act and every library description are read into three vectors each, mean-pooled over their tokens,
and their tokens with rarity weights (Features):

- semantic: the pretrained sentence encoder's states (all-MiniLM-L6-v2 is trained for similarity, so
  "salute" is near "greeting crew coming aboard" without any motion training data);
- lexical: the encoder's word embeddings (which words are said);
- distinctive: the word embeddings weighted by rarity, a / (a + p(word)) with p the word's frequency in
  the training texts (smooth inverse frequency): "baffled", "thumbs", "floor" count, "I" and "the" do not;
- words: the token ids with the same rarity weights.

score(act, motion) = (1 - q) * [cos(Ps a, Ps m) over the semantic vectors
                              + cos(Pl a, Pl m) over the lexical ones]
                     + q * [cos(a, m) over the semantic vectors + cos(a, m) over the lexical ones]
                     + word_weight * cos(a, m) over the distinctive ones
                     + shared_weight * (share of the act's rarity weight in words the description also uses).

Ps and Pl start as the identity and are trained on the annotated variants of the training split, each
on its own similarity, with a random share of each class's motions left out of every batch, so they
learn what in an utterance points at a description, not which motions the data favours. The
untrained word terms (distinctive and shared) keep a new motion's own words decisive: a motion added by
file is scored like a known one, without retraining. Even so the projections lean toward what the
annotated data calls each known motion; q (pretrained_share), a share of the pretrained encoder's own
similarity, keeps part of the dense terms free of that. The shared-word term counts only words both
texts say, so it adds nothing for descriptions that merely sound alike (the averaged distinctive vectors
do; leaning on the shared words, known motions lose fewer acts to new ones). The projections read only
frozen states, so they are trained apart from the encoder, in seconds, after its epochs
(planners/local/variant_training.py).

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

# a in a / (a + p(word)): words rarer than this in the training texts weigh about 1 in the distinctive
# vectors. On the held-out training slice and the new-motion test, 3e-4 traded 2 points of known-motion
# accuracy for new motions picked from their own words; 1e-3 and 1e-4 did no better.
SMOOTHING = 3e-4


def new_projections(width: int) -> tuple:
    """(semantic projection, lexical projection), identity-initialised."""
    import torch

    projections = (torch.nn.Linear(width, width, bias=False), torch.nn.Linear(width, width, bias=False))
    for projection in projections:
        torch.nn.init.eye_(projection.weight)
    return projections


def unit(projection, vectors):
    """The vectors through the projection, each row normalised (torch)."""
    from torch.nn.functional import normalize

    return normalize(projection(vectors), dim=-1)


@dataclass
class Features:
    """What the variant score reads of N texts (acts or descriptions)."""

    semantic: np.ndarray  # (N, D), normalised
    lexical: np.ndarray  # (N, D), normalised
    distinctive: np.ndarray  # (N, D), normalised
    words: list[tuple[np.ndarray, np.ndarray]]  # per text: (token ids, rarity weights)

    def __getitem__(self, k: int) -> Features:
        return Features(self.semantic[k:k + 1], self.lexical[k:k + 1], self.distinctive[k:k + 1],
                        [self.words[k]])

    @classmethod
    def stacked(cls, parts: list[Features], width: int) -> Features:
        if not parts:
            return cls(*(np.zeros((0, width), dtype=np.float32) for _ in range(3)), [])
        dense = (np.concatenate([getattr(p, name) for p in parts])
                 for name in ("semantic", "lexical", "distinctive"))
        return cls(*dense, [w for p in parts for w in p.words])


@dataclass
class Weights:
    """How the variant score's terms are weighed (conf/planner/local.yaml)."""

    word: float  # the distinctive vectors' cosine
    shared: float  # the share of the act's rarity weight in words the description also uses
    pretrained_share: float  # of the semantic and lexical cosines, the share taken of the unprojected vectors


class Compared(NamedTuple):
    """What the score compares of N texts (torch vectors)."""

    projected_semantic: object  # (N, D) through the semantic projection, normalised
    projected_lexical: object  # (N, D) through the lexical projection, normalised
    semantic: object  # (N, D) as read
    lexical: object  # (N, D) as read
    distinctive: object  # (N, D) as read
    words: object  # acts: per text (token ids, rarity weights); motions: word_presence() of theirs


def projected(projections, features: Features) -> Compared:
    import torch

    semantic, lexical = torch.from_numpy(features.semantic), torch.from_numpy(features.lexical)
    return Compared(unit(projections[0], semantic), unit(projections[1], lexical),
                    semantic, lexical, torch.from_numpy(features.distinctive), features.words)


def word_presence(motion_words: list[tuple[np.ndarray, np.ndarray]]) -> np.ndarray:
    """(M, V): 1 where motion m's description has token id v (V: one past the largest id present)."""
    vocabulary = 1 + max((int(ids.max()) for ids, _ in motion_words if len(ids)), default=0)
    present = np.zeros((len(motion_words), vocabulary), dtype=np.float32)
    for m, (ids, _) in enumerate(motion_words):
        present[m, ids] = 1.0
    return present


def shared_words(words: tuple[np.ndarray, np.ndarray], present: np.ndarray) -> np.ndarray:
    """(M,): per motion, the share of the act's rarity weight carried by tokens its description also has.
    present: word_presence() of the motions."""
    ids, weights = words
    known = ids < present.shape[1]
    return present[:, ids[known]] @ weights[known] / max(float(weights.sum()), 1e-9)


def scores(act: Compared, motions: Compared, weights: Weights) -> np.ndarray:
    """(A, M) variant scores of A acts against M motions, both as projected() gives them, with the
    motions' words tabulated by word_presence()."""
    trained = (act.projected_semantic @ motions.projected_semantic.T
               + act.projected_lexical @ motions.projected_lexical.T)
    pretrained = act.semantic @ motions.semantic.T + act.lexical @ motions.lexical.T
    q = weights.pretrained_share
    dense = (1 - q) * trained + q * pretrained + weights.word * act.distinctive @ motions.distinctive.T
    shared = np.stack([shared_words(words, motions.words) for words in act.words])
    return dense.numpy() + weights.shared * shared


@dataclass(frozen=True)
class ClassMove:
    """How far a motion that fits an act better than its class's own motions may move the act's class
    (conf/planner/local.yaml)."""

    annotated: float  # toward a motion the training data annotates: the class head has read acts about it
    new: float  # toward one it never saw: the motion's description is the only evidence for its uses


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
        self._cached: tuple = (-1, [], np.zeros(0, dtype=int), np.zeros(0, dtype=bool), ())

    def _underrated(self, entries: dict[str, tuple[str, tuple[str, ...]]]) -> np.ndarray:
        """Per text of the catalogue: -log p(its motion's class) as the class head reads it for an example
        utterance, 0 for a description (or without read_classes)."""
        evidence = [(CLASSES.index(cls), k > 0) for cls, texts in entries.values() for k in range(len(texts))]
        examples = [text for _, texts in entries.values() for text in texts[1:]]
        underrated = np.zeros(len(evidence))
        if self.read_classes is None or not examples:
            return underrated
        is_example = np.array([example for _, example in evidence])
        own_class = np.array([c for c, example in evidence if example])
        underrated[is_example] = -self.read_classes(examples)[np.arange(len(examples)), own_class]
        return underrated

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
        import torch

        cached = self._cached  # one read: another thread may replace it
        if cached[0] != version:
            entries = catalogue()
            texts = [text for _, evidence in entries.values() for text in evidence]
            with torch.inference_mode():
                described = projected(self.projections, self.describe(texts))
                motions = described._replace(words=word_presence(described.words))
            classes = np.array([CLASSES.index(c) for c, _ in entries.values()], dtype=int)
            is_annotated = np.array([name in self.annotated for name in entries], dtype=bool)
            owner = np.repeat(np.arange(len(entries)), [len(evidence) for _, evidence in entries.values()])
            cached = self._cached = (version, list(entries), classes, is_annotated,
                                     (motions, owner, self._underrated(entries)))
        _, names, classes, is_annotated, (motions, owner, underrated) = cached
        own = CLASSES.index(cls)
        selectable = np.array([name not in barred for name in names], dtype=bool)
        members = np.flatnonzero((classes == own) & selectable)
        if not len(members):
            return cls, None
        row, credit = np.full(len(names), -np.inf), np.zeros(len(names))
        with torch.inference_mode():  # a motion's score: its best-fitting text (description or example)
            fits = scores(projected(self.projections, act), motions, self.weights)[0]
        np.maximum.at(row, owner, fits)
        best_text = fits >= row[owner]
        np.maximum.at(credit, owner[best_text], underrated[best_text])  # what its best example gets back
        own_best = members[int(np.argmax(row[members]))]
        chosen, best_total = own_best, np.log(proba[own] + 1e-12) + credit[own_best]
        weight = np.where(is_annotated, move.annotated, move.new)
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
