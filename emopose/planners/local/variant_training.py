"""Training the variant projections (planners/local/variant_score.py) on the annotated acts.

Each projection learns on its own similarity: cross-entropy of an act's annotated motion against the
other motions of its class, with a random share of each class's motions left out of every batch
(TrainingConfig.variant_holdout), so it learns what in an utterance points at a description, not
which motions the data favours. The projections read only frozen states, so this runs after the
encoder's epochs, on the cached act vectors, in seconds (planners/local/training.py).
"""

from __future__ import annotations

import random
import sys
from dataclasses import dataclass

from emopose import CLASSES
from emopose.planners.local.config import TrainingConfig
from emopose.planners.local.variant_score import unit


def similarity(projection, acts, motions):
    """(A, M) cosine similarity of A act vectors and M motion vectors after the projection (torch)."""
    return unit(projection, acts) @ unit(projection, motions).T


@dataclass
class AnnotatedAct:
    """One training act with an annotated variant: its class, motion and (semantic, lexical) vectors."""

    label: str
    variant: str
    semantic: object  # torch (D,)
    lexical: object  # torch (D,)


@dataclass
class VariantTask:
    """The acts and the motions they choose among, as tensors (torch)."""

    members: dict[int, list[int]]  # class index -> its motions' indices
    same_class: object  # (A, M) bool: motion m is of act a's class
    target: object  # (A,) the annotated motion's index
    channels: tuple  # per projection: (projection, act vectors (A, D), motion vectors (M, D))


def variant_task(projections, acts: list[AnnotatedAct], described: dict[str, tuple]) -> VariantTask | None:
    """The task over the motions that have a competitor in their class; None when no act is about one.
    described: motion name -> (class, semantic (D,), lexical (D,))."""
    import torch

    names = [n for n in described if sum(described[m][0] == described[n][0] for m in described) > 1]
    acts = [a for a in acts if a.variant in names]
    if not acts:
        return None
    motion_class = [CLASSES.index(described[n][0]) for n in names]
    motion_semantic = torch.stack([described[n][1] for n in names])
    motion_lexical = torch.stack([described[n][2] for n in names])
    members = {c: [k for k, m in enumerate(motion_class) if m == c] for c in set(motion_class)}
    act_class = torch.tensor([CLASSES.index(a.label) for a in acts])
    target = torch.tensor([names.index(a.variant) for a in acts])
    act_semantic = torch.stack([a.semantic for a in acts])
    act_lexical = torch.stack([a.lexical for a in acts])
    same_class = act_class.unsqueeze(1) == torch.tensor(motion_class).unsqueeze(0)  # (A, M)
    channels = ((projections[0], act_semantic, motion_semantic),
                (projections[1], act_lexical, motion_lexical))
    return VariantTask(members, same_class, target, channels)


def batch_loss(task: VariantTask, batch, left_out, logit_scale: float):
    """The batch's summed cross-entropy over both projections; None when no act in it can teach anything:
    one whose motion is left out, or that would have no competitor, teaches nothing here."""
    import torch

    allowed = task.same_class[batch] & ~left_out
    kept = allowed[torch.arange(len(batch)), task.target[batch]] & (allowed.sum(1) > 1)
    if not kept.any():
        return None
    rows = batch[kept]
    # each projection learns on its own: trained together, one leaned on the other (held-out exact
    # variant 62 % against 64 %)
    return sum(torch.nn.functional.cross_entropy(
        (similarity(projection, acts_in[rows], motions) * logit_scale).masked_fill(~allowed[kept], -1e4),
        task.target[rows]) for projection, acts_in, motions in task.channels)


def fit_variants(projections, acts: list[AnnotatedAct], described: dict[str, tuple], cfg: TrainingConfig,
                 progress: bool = True) -> None:
    """Train the projections in place (cfg.variant_epochs passes, cfg.variant_holdout of each class's
    motions left out of every batch). described: motion name -> (class, semantic (D,), lexical (D,))."""
    import torch
    from tqdm import tqdm

    task = variant_task(projections, acts, described)
    if task is None:
        return
    rng = random.Random(cfg.seed)
    generator = torch.Generator().manual_seed(cfg.seed)
    optimizer = torch.optim.AdamW([q for p in projections for q in p.parameters()], lr=cfg.head_lr,
                                  weight_decay=0.01)
    for _ in tqdm(range(cfg.variant_epochs), desc="local planner: variant projections", unit="epoch",
                  file=sys.stderr, disable=not progress):
        for batch in torch.randperm(len(task.target), generator=generator).split(cfg.batch_size):
            left_out = torch.zeros(task.same_class.shape[1], dtype=torch.bool)
            for ks in task.members.values():
                left_out[rng.sample(ks, round(cfg.variant_holdout * len(ks)))] = True
            loss = batch_loss(task, batch, left_out, cfg.logit_scale)
            if loss is None:
                continue
            optimizer.zero_grad()
            loss.backward()
            optimizer.step()
