"""The local planner's training losses of one batch, summed (planners/local/training.py runs them):

- act classes (cross-entropy over every annotated act, pooled class states);
- relevance (binary per item read after a history: its own dialogue's, or a distractor's unrelated one);
- boundaries (binary, at every candidate segment boundary) and the semi-CRF likelihood of the
  annotated split against every other split of the segments (planners/local/semi_crf.py);
- anchors (binary per token: inside the annotated trigger phrase) and their onsets (cross-entropy over
  the tokens of the act each anchor lies in: which one the anchor starts at).

Every head runs once over the whole batch: the act, span and segment vectors are gathered from one
cumulative sum (per-example head calls took half of each step).
"""

from __future__ import annotations

import itertools

from emopose import CLASSES
from emopose.planners.local.data import Example
from emopose.planners.local.heads import boundary_features, token_range
from emopose.planners.local.model import ActModel
from emopose.planners.local.semi_crf import log_partition, split_score

AnnotatedSplits = dict[int, tuple[list, list[tuple[int, int]], list[int]]]


def batch_loss(model: ActModel, batch: list[Example], tokens, lower):
    """The summed losses of one batch (terms added in a fixed order: the sums are repeatable)."""
    import torch
    from torch.nn.functional import binary_cross_entropy_with_logits as bce
    from torch.nn.functional import cross_entropy

    cfg = model.config
    class_states = model.upper(lower, tokens.inputs["attention_mask"]).float()
    pool = BatchPool(class_states, tokens)
    acts = pool.add([(k, a.start, a.end) for k, e in enumerate(batch) for a in e.acts])
    act_labels = torch.tensor([CLASSES.index(a.label) for e in batch for a in e.acts])
    split = [k for k, e in enumerate(batch) if len(e.pieces) > 1]
    pieces = {k: pool.add([(k, p.start, p.end) for p in batch[k].pieces]) for k in split}
    splits = annotated_splits(batch, pool) if cfg.split_loss_weight else {}
    vectors = pool.vectors()
    loss = cross_entropy(model.act_head(vectors[acts]) * cfg.logit_scale, act_labels)
    after_history = [k for k, read_after in enumerate(tokens.prefixed) if read_after]
    if after_history and cfg.relevance_loss_weight:  # read from [CLS], which attends to history and utterance
        bears = torch.tensor([float(batch[k].history_bears) for k in after_history])
        logits = model.relevance_head(class_states[after_history, 0]).squeeze(-1)
        loss = loss + cfg.relevance_loss_weight * bce(logits, bears)
    openings = vectors.new_zeros(0)
    if split:
        left = vectors[[r for k in split for r in pieces[k][:-1]]]
        right = vectors[[r for k in split for r in pieces[k][1:]]]
        openings = model.boundary_head(boundary_features(left, right)).squeeze(-1)
        labels = torch.tensor([b for k in split for b in batch[k].boundaries], dtype=torch.float32)
        loss = loss + bce(openings, labels)
    if splits:  # single-segment items too: their one split is a class likelihood of the whole utterance
        first = dict(zip(split, itertools.accumulate([0] + [len(pieces[k]) - 1 for k in split])))
        loss = loss + cfg.split_loss_weight * split_loss(model, batch, splits, vectors, openings, first)
    anchored = [k for k, e in enumerate(batch) if e.anchors]
    if anchored:
        loss = loss + cfg.anchor_loss_weight * anchor_loss(model, batch, tokens, class_states, anchored)
        loss = loss + cfg.anchor_loss_weight * onset_loss(model, batch, tokens, class_states, anchored)
    return loss


def annotated_splits(batch: list[Example], pool: BatchPool) -> AnnotatedSplits:
    """Per item with an annotated split: (that split, every candidate span of its segments, the spans'
    rows in the pool)."""
    splits = {}
    for k, example in enumerate(batch):
        gold = example.gold_split()
        if gold is None:
            continue
        n = len(example.pieces)
        spans = [(i, j) for i in range(n) for j in range(i + 1, n + 1)]
        rows = pool.add([(k, example.pieces[i].start, example.pieces[j - 1].end) for i, j in spans])
        splits[k] = (gold, spans, rows)
    return splits


def split_loss(model: ActModel, batch: list[Example], splits: AnnotatedSplits, vectors, openings,
               first: dict[int, int]):
    """The mean -log P(annotated split) over the items; first: an item's first row in openings."""
    import torch

    span_rows = [r for _, _, rows in splits.values() for r in rows]
    scores = model.act_head(vectors[span_rows]) * model.config.logit_scale
    offsets = dict(zip(splits, itertools.accumulate([0] + [len(spans) for _, spans, _ in splits.values()])))
    losses = [split_nll(len(batch[k].pieces), spans, scores[offsets[k]:offsets[k] + len(spans)], gold,
                        openings[first.get(k, 0):first.get(k, 0) + len(batch[k].pieces) - 1])
              for k, (gold, spans, _) in splits.items()]
    return torch.stack(losses).mean()


def anchor_loss(model: ActModel, batch: list[Example], tokens, class_states, anchored: list[int]):
    """Binary per token of the anchored items: inside an annotated trigger phrase or not."""
    import torch
    from torch.nn.functional import binary_cross_entropy_with_logits as bce

    logits = model.anchor_head(class_states).squeeze(-1)
    positions = [(k, t) for k in anchored for t in tokens.real[k]]
    labels = [float(any(a <= s < b for a, b in batch[k].anchors)) for k in anchored for s in tokens.starts[k]]
    rows, cols = zip(*positions)
    return bce(logits[list(rows), list(cols)], torch.tensor(labels))


def onset_loss(model: ActModel, batch: list[Example], tokens, class_states, anchored: list[int]):
    """Mean cross-entropy of each anchor's first token among the tokens of the act it lies in."""
    import torch
    from torch.nn.functional import cross_entropy

    logits = model.onset_head(class_states).squeeze(-1)
    losses = []
    for k in anchored:
        starts, real = tokens.starts[k], tokens.real[k]
        for begin, _ in batch[k].anchors:
            act = next((a for a in batch[k].acts if a.start <= begin < a.end), None)
            if act is None:
                continue
            first, last = token_range(starts, act.start, act.end)
            target = token_range(starts, begin, begin + 1)[0]
            if first <= target < last:
                row = logits[k, real[first]:real[last - 1] + 1]
                losses.append(cross_entropy(row.unsqueeze(0), torch.tensor([target - first])))
    return torch.stack(losses).mean() if losses else logits.new_zeros(())


class BatchPool:
    """Normalised means of a batch's states over character spans of its utterances, gathered at once:
    add() the spans (example index, start, end), then vectors() pools all of them."""

    def __init__(self, states, tokens) -> None:
        import torch

        zeros = states.new_zeros(states.shape[0], 1, states.shape[2])
        self.summed = torch.cat([zeros, states.cumsum(1)], dim=1)
        self.starts = tokens.starts
        self.first_position = [real[0] for real in tokens.real]
        if any(real != list(range(real[0], real[0] + len(real))) for real in tokens.real):
            raise ValueError("an utterance's tokens are not contiguous in its input")  # pooling assumes it
        self.ranges: list[tuple[int, int, int]] = []

    def add(self, spans: list[tuple[int, int, int]]) -> list[int]:
        """Row indices (into vectors()) of the spans' pooled states."""
        rows = list(range(len(self.ranges), len(self.ranges) + len(spans)))
        for k, start, end in spans:
            first, last = token_range(self.starts[k], start, end)
            self.ranges.append((k, self.first_position[k] + first, self.first_position[k] + last))
        return rows

    def vectors(self):
        import torch

        k, a, b = (torch.tensor(column) for column in zip(*self.ranges))
        means = (self.summed[k, b] - self.summed[k, a]) / (b - a).unsqueeze(1).to(self.summed.dtype)
        return torch.nn.functional.normalize(means, dim=-1)


def split_nll(n: int, spans: list[tuple[int, int]], span_scores, gold: list[tuple[tuple[int, int], str]],
              openings):
    """-log P(gold split | utterance) under the semi-CRF over every split of its n segments."""
    acts = [(spans.index(span), CLASSES.index(label)) for span, label in gold]
    return log_partition(n, spans, span_scores, openings) - split_score(acts, spans, span_scores, openings)
