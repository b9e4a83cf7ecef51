"""The local planner's variant choice: the motion of the act's class whose description fits its words.

An act and every library description are read into three vectors each, mean-pooled over their tokens:

- semantic: the pretrained sentence encoder's states (all-MiniLM-L6-v2 is trained for similarity, so
  "salute" is near "greeting crew coming aboard" without any motion training data);
- lexical: the encoder's word embeddings (which words are said);
- distinctive: the word embeddings weighted by rarity, a / (a + p(word)) with p the word's frequency in
  the training texts (smooth inverse frequency): "baffled", "thumbs", "floor" count, "I" and "the" do not.

score(act, motion) = cos(Ps a, Ps m) over the semantic vectors + cos(Pl a, Pl m) over the lexical ones
                     + words_weight * cos(a, m) over the distinctive ones, untrained.

Ps and Pl start as the identity and are trained on the annotated variants of the training split, each
on its own similarity, with a random share of each class's motions left out of every batch, so they
learn what in an utterance points at a description, not which motions the data favours. The untrained
distinctive term keeps a new motion's own words decisive: a motion added by file is scored like a known
one, without retraining. The projections read only frozen states, so they are trained apart from the
encoder, in seconds, after its epochs (planners/local_training.py).

The class is chosen with the motion (VariantChooser.choose): log p(class) + class_weight * score, so a
motion that fits an act's words clearly better can move an act the split model was unsure about.
"""

from __future__ import annotations

import random
import sys
from collections.abc import Callable
from dataclasses import dataclass

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


def similarity(projection, acts, motions):
    """(A, M) cosine similarity of A act vectors and M motion vectors after the projection (torch)."""
    return unit(projection, acts) @ unit(projection, motions).T


def projected(projections, vectors: tuple) -> tuple:
    """(semantic, lexical, distinctive) row vectors as the score compares them: the first two through
    their projections, normalised (torch)."""
    return unit(projections[0], vectors[0]), unit(projections[1], vectors[1]), vectors[2]


def scores(act: tuple, motions: tuple, words_weight: float):
    """(A, M) variant scores of A acts against M motions, both as projected() gives them."""
    return act[0] @ motions[0].T + act[1] @ motions[1].T + words_weight * act[2] @ motions[2].T


@dataclass
class AnnotatedAct:
    """One training act with an annotated variant: its class, motion and (semantic, lexical) vectors."""

    label: str
    variant: str
    semantic: object  # torch (D,)
    lexical: object  # torch (D,)


def fit_variants(projections, acts: list[AnnotatedAct], described: dict[str, tuple], cfg,
                 progress: bool = True) -> None:
    """Train the projections in place: cross-entropy of each act's annotated motion against the other
    motions of its class that are not left out of the batch (cfg.variant_holdout of each class's
    motions, drawn per batch), for each projection's own similarity. described: motion name ->
    (class, semantic (D,), lexical (D,))."""
    import torch
    from tqdm import tqdm

    names = [n for n in described if sum(described[m][0] == described[n][0] for m in described) > 1]
    acts = [a for a in acts if a.variant in names]
    if not acts:
        return
    motion_class = [CLASSES.index(described[n][0]) for n in names]
    motion_semantic = torch.stack([described[n][1] for n in names])
    motion_lexical = torch.stack([described[n][2] for n in names])
    members = {c: [k for k, m in enumerate(motion_class) if m == c] for c in set(motion_class)}
    act_class = torch.tensor([CLASSES.index(a.label) for a in acts])
    target = torch.tensor([names.index(a.variant) for a in acts])
    act_semantic = torch.stack([a.semantic for a in acts])
    act_lexical = torch.stack([a.lexical for a in acts])
    same_class = act_class.unsqueeze(1) == torch.tensor(motion_class).unsqueeze(0)  # (A, M)
    channels = ((projections[0], act_semantic, motion_semantic), (projections[1], act_lexical, motion_lexical))
    rng = random.Random(cfg.seed)
    generator = torch.Generator().manual_seed(cfg.seed)
    optimizer = torch.optim.AdamW([q for p in projections for q in p.parameters()], lr=cfg.head_lr,
                                  weight_decay=0.01)
    for _ in tqdm(range(cfg.variant_epochs), desc="local planner: variant projections", unit="epoch",
                  file=sys.stderr, disable=not progress):
        for batch in torch.randperm(len(acts), generator=generator).split(cfg.batch_size):
            left_out = torch.zeros(len(names), dtype=torch.bool)
            for ks in members.values():
                left_out[rng.sample(ks, round(cfg.variant_holdout * len(ks)))] = True
            allowed = same_class[batch] & ~left_out
            # an act whose motion is left out, or that would have no competitor, teaches nothing here
            kept = allowed[torch.arange(len(batch)), target[batch]] & (allowed.sum(1) > 1)
            if not kept.any():
                continue
            rows = batch[kept]
            # each projection learns on its own: trained together, one leaned on the other (held-out
            # exact variant 62 % against 64 %)
            loss = sum(torch.nn.functional.cross_entropy(
                (similarity(projection, acts_in[rows], motions) * cfg.logit_scale).masked_fill(~allowed[kept], -1e4),
                target[rows]) for projection, acts_in, motions in channels)
            optimizer.zero_grad()
            loss.backward()
            optimizer.step()


class VariantChooser:
    """Inference: an act's class and motion. The descriptions are read and projected once per library
    version. describe(texts) -> (semantic, lexical, distinctive), each (N, D), normalised numpy arrays."""

    def __init__(self, projections, describe, words_weight: float) -> None:
        self.projections, self.describe, self.words_weight = projections, describe, words_weight
        self._cached: tuple = (-1, [], np.zeros(0, dtype=int), ())

    def choose(self, catalogue: Callable[[], dict[str, tuple[str, str]]], version: int, cls: str,
               proba: np.ndarray, vectors: tuple[np.ndarray, ...], class_weight: float,
               excluded: frozenset[str] = frozenset()) -> tuple[str, str | None]:
        """(class, motion) for an act the split model reads as cls with class probabilities proba: the
        class c maximising log proba[c] + class_weight * (its best motion's score), and that motion. With
        class_weight 0, or when cls has no motion, the class stays cls; otherwise a class the model found
        less likely wins only when one of its motions fits the act's words clearly better (a new "finger
        wag" motion for a scolding the model half read as comforting). Classes in excluded (the
        neighbouring acts') are never moved to. catalogue() -> the live library's selectable motions,
        name -> (class, description text), read again when the library's version changes. vectors: the
        act's, as describe gives them."""
        import torch

        cached = self._cached  # one read: another thread may replace it
        if cached[0] != version:
            entries = catalogue()
            with torch.inference_mode():
                motions = projected(self.projections, tuple(torch.from_numpy(v) for v in
                                                            self.describe([text for _, text in entries.values()])))
            classes = np.array([CLASSES.index(c) for c, _ in entries.values()], dtype=int)
            cached = self._cached = (version, list(entries), classes, motions)
        _, names, classes, motions = cached
        own = classes == CLASSES.index(cls)
        if not own.any():
            return cls, None
        with torch.inference_mode():
            act = projected(self.projections, tuple(torch.from_numpy(v[None]) for v in vectors))
            row = scores(act, motions, self.words_weight)[0].numpy()
        if class_weight:
            others = ~own & ~np.isin(classes, [CLASSES.index(c) for c in excluded])
            # per motion: its class's log-probability plus the weighted fit; the best motion names the class
            total = np.where(own | others, np.log(proba[classes] + 1e-12) + class_weight * row, -np.inf)
        else:
            total = np.where(own, row, -np.inf)
        best = int(np.argmax(total))
        return CLASSES[classes[best]], names[best]
