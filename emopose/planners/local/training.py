"""Training the local planner's model (planners/local_model.py) on examples from planners/local_data.py.

The frozen lower layers run once over every example (their outputs are cached in float16, with each
annotated act's pooled semantic and lexical vectors); each epoch then runs only the fine-tuned top
layers and the heads over the cache, which is what makes first-use training a few minutes on two cores. Matrix
products run in bfloat16 (autocast) where the CPU supports it natively; weights and optimiser state
stay float32; the learning rates warm up and decay linearly when lr_schedule says so. Every pass shows
a progress bar with ETA on stderr. Losses, summed:

- act classes (cross-entropy over every annotated act, pooled class states);
- boundaries (binary, at every candidate segment boundary) and the semi-CRF likelihood of the
  annotated split against every other split of the segments (planners/semi_crf.py);
- anchors (binary per token: inside the annotated trigger phrase);
- relevance (binary per item read after a history: its own dialogue's, or a distractor's unrelated one).

The variant projections read only frozen states, so they are trained after the epochs, on the cached
act vectors, in seconds (planners/local_variants.py).
"""

from __future__ import annotations

import itertools
import logging
import random
import sys

from emopose import CLASSES
from emopose.planners.local.data import Example
from emopose.planners.local.heads import boundary_features, pooled, token_range
from emopose.planners.local.model import ActModel
from emopose.planners.local.semi_crf import log_partition, split_score
from emopose.planners.local.variants import AnnotatedAct, fit_variants

log = logging.getLogger(__name__)


def describe(model: ActModel, catalogue: dict[str, tuple[str, str]]) -> dict[str, tuple]:
    """The motions' description texts as {name: (class, semantic (D,), lexical (D,))} tensors."""
    import torch

    if not catalogue:
        return {}
    with torch.no_grad():
        tokens = model.tokens([text for _, text in catalogue.values()])
        wholes = [[(0, len(real))] for real in tokens.real]
        vectors = variant_inputs(model, tokens, model.lower(tokens.inputs), wholes)
        return {name: (cls, *pairs[0]) for (name, (cls, _)), pairs in zip(catalogue.items(), vectors)}


def variant_inputs(model: ActModel, tokens, lower, ranges: list[list[tuple[int, int]]]) -> list[list[tuple]]:
    """Per text, the (semantic, lexical) vectors of its token ranges: what the variant projections read."""
    semantic = model.sentence(lower, tokens.inputs["attention_mask"]).float()
    words = model.words(tokens.inputs)
    return [list(zip(pooled(semantic[k, tokens.real[k]], r), pooled(words[k, tokens.real[k]], r))) if r else []
            for k, r in enumerate(ranges)]


def fit(model: ActModel, examples: list[Example], catalogue: dict[str, tuple[str, str]] | None = None,
        progress: bool = True) -> None:
    """Train the model's top layers and heads in place, repeatably: PyTorch's deterministic kernels are
    on for the training (two trainings otherwise differed by up to 0.02 in a weight, which moved a few
    suite items). catalogue: motion name -> (class, description)."""
    import torch

    previous = torch.are_deterministic_algorithms_enabled(), torch.is_deterministic_algorithms_warn_only_enabled()
    torch.use_deterministic_algorithms(True)
    try:
        train(model, examples, catalogue or {}, progress)
    finally:
        torch.use_deterministic_algorithms(previous[0], warn_only=previous[1])


def train(model: ActModel, examples: list[Example], catalogue: dict[str, tuple[str, str]], progress: bool) -> None:
    import torch
    from tqdm import tqdm

    cfg = model.config
    torch.manual_seed(cfg.seed)
    rng = random.Random(cfg.seed)
    for p in model.body.parameters():
        p.requires_grad_(False)
    top = model.body.encoder.layer[model.frozen_depth:]
    for p in top.parameters():
        p.requires_grad_(True)
    model.learn_words(sorted({e.text for e in examples}))
    model.annotated_motions = sorted({v for e in examples for v in e.variants if v})
    # Batches of inputs with the same token count (history prefix included) are barely padded (sorting
    # by the utterance's characters left a third of every batch padding); their order is shuffled each epoch.
    lengths = model.input_lengths([e.text for e in examples], [e.history for e in examples])
    by_length = [examples[k] for k in sorted(range(len(examples)), key=lengths.__getitem__)]
    batches = [by_length[k:k + cfg.batch_size] for k in range(0, len(by_length), cfg.batch_size)]
    bf16 = torch.ops.mkldnn._is_mkldnn_bf16_supported()
    cache, annotated = [], []
    with torch.no_grad(), torch.autocast("cpu", dtype=torch.bfloat16, enabled=bf16):
        for batch in tqdm(batches, desc="local planner: frozen layers", unit="batch", file=sys.stderr,
                          disable=not progress):
            tokens = model.tokens([e.text for e in batch], [e.history for e in batch])
            lower = model.lower(tokens.inputs)
            if catalogue and any(e.variants for e in batch):  # the pretrained top and the words: variants
                annotated += annotated_acts(model, batch, tokens, lower)
            cache.append((batch, tokens, lower.half()))
    heads = [q for h in (model.act_head, model.boundary_head, model.anchor_head, model.relevance_head)
             for q in h.parameters()]
    optimizer = torch.optim.AdamW([{"params": list(top.parameters()), "lr": cfg.lr},
                                   {"params": heads, "lr": cfg.head_lr}], weight_decay=0.01)
    scheduler = torch.optim.lr_scheduler.LambdaLR(optimizer, learning_rate_factor(cfg, cfg.epochs * len(cache)))
    top.train()
    # PyTorch's CPU flash-attention backward took a third of every step at these lengths; the plain
    # softmax(QK^T)V attention computes the same and trains about 30 % faster. Inference keeps SDPA.
    attention = model.body.config._attn_implementation
    model.body.set_attn_implementation("eager")
    try:
        for epoch in range(cfg.epochs):
            rng.shuffle(cache)
            total = 0.0
            bar = tqdm(cache, desc=f"local planner: epoch {epoch + 1}/{cfg.epochs}", unit="batch",
                       file=sys.stderr, disable=not progress)
            for batch, tokens, lower in bar:
                with torch.autocast("cpu", dtype=torch.bfloat16, enabled=bf16):
                    loss = batch_loss(model, batch, tokens, lower.float())
                optimizer.zero_grad()
                loss.backward()
                optimizer.step()
                scheduler.step()
                total += loss.item() * len(batch)
                bar.set_postfix(loss=f"{loss.item():.3f}")
            log.info("local planner epoch %d/%d: loss %.4f", epoch + 1, cfg.epochs, total / len(examples))
    finally:
        model.body.set_attn_implementation(attention)
    top.eval()
    fit_variants(model.variant_projections, annotated, describe(model, catalogue), cfg, progress)


def learning_rate_factor(cfg, steps: int):
    """Step -> multiplier of the configured learning rates (lr_schedule)."""
    if cfg.lr_schedule == "constant":
        return lambda step: 1.0
    warmup = max(1, round(0.05 * steps))
    return lambda step: min((step + 1) / warmup, max(0.0, (steps - step) / max(1, steps - warmup)))


def annotated_acts(model: ActModel, batch: list[Example], tokens, lower) -> list[AnnotatedAct]:
    """The batch's acts with an annotated variant, with their pooled semantic and lexical vectors."""
    ranges = [[token_range(tokens.starts[k], a.start, a.end) for a in e.acts] if e.variants else []
              for k, e in enumerate(batch)]
    return [AnnotatedAct(act.label, variant, semantic, lexical)
            for e, pairs in zip(batch, variant_inputs(model, tokens, lower, ranges))
            for act, variant, (semantic, lexical) in zip(e.acts, e.variants, pairs)]


def batch_loss(model: ActModel, batch: list[Example], tokens, lower):
    """The summed losses of one batch. Every head runs once over the whole batch: the act, span and
    segment vectors are gathered from one cumulative sum (per-example head calls took half of each step)."""
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
    gold = {k: e.gold_split() for k, e in enumerate(batch)} if cfg.split_loss_weight else {}
    gold = {k: g for k, g in gold.items() if g is not None}
    spans = {k: [(i, j) for i in range(len(batch[k].pieces)) for j in range(i + 1, len(batch[k].pieces) + 1)]
             for k in gold}
    span_rows = {k: pool.add([(k, batch[k].pieces[i].start, batch[k].pieces[j - 1].end) for i, j in spans[k]])
                 for k in gold}
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
    if gold:  # single-segment items too: their one split is a class likelihood of the whole utterance
        first = dict(zip(split, itertools.accumulate([0] + [len(pieces[k]) - 1 for k in split])))
        scores = model.act_head(vectors[[r for k in gold for r in span_rows[k]]]) * cfg.logit_scale
        offsets = dict(zip(gold, itertools.accumulate([0] + [len(spans[k]) for k in gold])))
        losses = [split_nll(len(batch[k].pieces), spans[k], scores[offsets[k]:offsets[k] + len(spans[k])], gold[k],
                            openings[first.get(k, 0):first.get(k, 0) + len(batch[k].pieces) - 1]) for k in gold]
        loss = loss + cfg.split_loss_weight * torch.stack(losses).mean()
    anchored = [k for k, e in enumerate(batch) if e.anchors]
    if anchored:
        logits = model.anchor_head(class_states).squeeze(-1)
        positions = [(k, t) for k in anchored for t in tokens.real[k]]
        labels = [float(any(a <= s < b for a, b in batch[k].anchors)) for k in anchored for s in tokens.starts[k]]
        rows, cols = zip(*positions)
        loss = loss + cfg.anchor_loss_weight * bce(logits[list(rows), list(cols)], torch.tensor(labels))
    return loss


class BatchPool:
    """Normalised means of a batch's states over character spans of its utterances, gathered at once:
    add() the spans (example index, start, end), then vectors() pools all of them."""

    def __init__(self, states, tokens) -> None:
        import torch

        self.summed = torch.cat([states.new_zeros(states.shape[0], 1, states.shape[2]), states.cumsum(1)], dim=1)
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
