"""The local planner's variant score: how well a motion's description (or example) fits an act's words.

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
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

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
