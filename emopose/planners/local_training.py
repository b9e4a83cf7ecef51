"""Training the local planner's model (planners/local_model.py) on examples from planners/local_data.py.

The frozen lower layers run once over every example (their outputs are cached in float16, with each
annotated act's pooled semantic vector); each epoch then runs only the fine-tuned top layers and the
heads over the cache, which is what makes first-use training a few minutes on two cores. Matrix
products run in bfloat16 (autocast) where the CPU supports it natively; weights and optimiser state
stay float32; the learning rates warm up and decay linearly when lr_schedule says so. Every pass shows
a progress bar with ETA on stderr. Losses, summed:

- act classes (cross-entropy over every annotated act, pooled class states);
- boundaries (binary, at every candidate segment boundary) and the semi-CRF likelihood of the
  annotated split against every other split of the segments (planners/semi_crf.py);
- anchors (binary per token: inside the annotated trigger phrase);
- variants: the projected act vector against the projected descriptions of its class's motions. A
  random share of each class's motions is left out of every batch (their acts skip the loss), so the
  projection cannot lean on a fixed set of motions and a new library entry competes on equal terms.
"""

from __future__ import annotations

import logging
import random
import sys

from emopose import CLASSES
from emopose.planners.local_context_model import ActModel
from emopose.planners.local_data import Example
from emopose.planners.local_model import Analysis, boundary_features, pooled
from emopose.planners.semi_crf import log_partition, split_score

log = logging.getLogger(__name__)


def describe(model: ActModel, catalogue: dict[str, tuple[str, str]]):
    """Semantic vectors of the motions' description texts, {name: (D,) tensor}."""
    import torch

    if not catalogue:
        return {}
    with torch.no_grad():
        tokens = model.tokens([text for _, text in catalogue.values()])
        semantic = model.sentence(model.lower(tokens.inputs), tokens.inputs["attention_mask"])
        return {name: pooled(semantic[k, tokens.real[k]], [(0, len(tokens.real[k]))])[0]
                for k, name in enumerate(catalogue)}


def fit(model: ActModel, examples: list[Example], catalogue: dict[str, tuple[str, str]] | None = None,
        progress: bool = True) -> None:
    """Train the model's top layers and heads in place. catalogue: motion name -> (class, description)."""
    import torch
    from tqdm import tqdm

    cfg = model.config
    torch.manual_seed(cfg.seed)
    rng = random.Random(cfg.seed)
    catalogue = catalogue or {}
    members = {c: [n for n, (cls, _) in catalogue.items() if cls == c] for c in CLASSES}
    described = describe(model, catalogue)
    for p in model.body.parameters():
        p.requires_grad_(False)
    top = model.body.encoder.layer[model.frozen_depth:]
    for p in top.parameters():
        p.requires_grad_(True)
    # Batches of similar length waste less compute on padding; their order is shuffled each epoch.
    by_length = sorted(examples, key=lambda e: len(e.text) + 40 * bool(e.history))  # a history adds ~40 chars
    batches = [by_length[k:k + cfg.batch_size] for k in range(0, len(by_length), cfg.batch_size)]
    bf16 = torch.ops.mkldnn._is_mkldnn_bf16_supported()
    cache = []
    with torch.no_grad(), torch.autocast("cpu", dtype=torch.bfloat16, enabled=bf16):
        for batch in tqdm(batches, desc="local planner: frozen layers", unit="batch", file=sys.stderr,
                          disable=not progress):
            tokens = model.tokens([e.text for e in batch], [e.history for e in batch])
            lower = model.lower(tokens.inputs)
            wanted = catalogue and any(e.variants for e in batch)  # the pretrained top: for variant labels
            semantic = model.sentence(lower, tokens.inputs["attention_mask"]) if wanted else None
            acts = [act_semantics(semantic, tokens, k, e) for k, e in enumerate(batch)]
            cache.append((batch, tokens, lower.half(), acts))
    heads = [q for h in model.heads for q in h.parameters()]
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
            for batch, tokens, lower, semantic in bar:
                left_out = {n for names in members.values()
                            for n in rng.sample(names, round(cfg.variant_holdout * len(names)))}
                with torch.autocast("cpu", dtype=torch.bfloat16, enabled=bf16):
                    loss = batch_loss(model, batch, tokens, lower.float(), semantic, members, described, left_out)
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


def learning_rate_factor(cfg, steps: int):
    """Step -> multiplier of the configured learning rates (lr_schedule)."""
    if cfg.lr_schedule == "constant":
        return lambda step: 1.0
    warmup = max(1, round(0.05 * steps))
    return lambda step: min((step + 1) / warmup, max(0.0, (steps - step) / max(1, steps - warmup)))


def act_semantics(semantic, tokens, k: int, example: Example):
    """The example's annotated acts' pooled semantic vectors (acts, D), or None without variant labels."""
    if semantic is None or not example.variants:
        return None
    analysis = Analysis(tokens.starts[k], None, None, None)
    ranges = [analysis.token_range(a.start, a.end) for a in example.acts]
    return pooled(semantic[k, tokens.real[k]].float(), ranges)


def batch_loss(model: ActModel, batch: list[Example], tokens, lower, semantic: list,
               members: dict[str, list[str]], described: dict, left_out: set[str]):
    import torch
    from torch.nn.functional import binary_cross_entropy_with_logits as bce
    from torch.nn.functional import cross_entropy, normalize

    cfg = model.config
    class_states = model.upper(lower, tokens.inputs["attention_mask"])
    act_vectors, act_labels, openings_all, boundary_labels = [], [], [], []
    anchor_logits, anchor_labels = [], []
    variant_losses, split_losses = [], []
    for k, example in enumerate(batch):
        states = class_states[k, tokens.real[k]]
        analysis = Analysis(tokens.starts[k], states, None, None)
        act_ranges = [analysis.token_range(a.start, a.end) for a in example.acts]
        act_vectors.append(pooled(states, act_ranges))
        act_labels += [CLASSES.index(a.label) for a in example.acts]
        if semantic[k] is not None:
            projected = normalize(model.variant_projection(semantic[k]), dim=-1)
            for act, vector, variant in zip(example.acts, projected, example.variants):
                candidates = [n for n in members.get(act.label, []) if n not in left_out]
                if variant in candidates and len(candidates) > 1:
                    described_here = torch.stack([described[n] for n in candidates])
                    targets = normalize(model.variant_projection(described_here), dim=-1)
                    variant_losses.append(cross_entropy((targets @ vector * cfg.logit_scale).unsqueeze(0),
                                                        torch.tensor([candidates.index(variant)])))
        openings = states.new_zeros(0)
        if len(example.pieces) > 1:
            ranges = [analysis.token_range(p.start, p.end) for p in example.pieces]
            openings = model.boundary_head(boundary_features(states, ranges)).squeeze(-1)
            openings_all.append(openings)
            boundary_labels += example.boundaries
        gold = example.gold_split() if cfg.split_loss_weight else None
        if gold is not None:
            split_losses.append(split_nll(model, example, gold, analysis, openings))
        if example.anchors:
            anchor_logits.append(model.anchor_head(states).squeeze(-1))
            anchor_labels += [float(any(a <= s < b for a, b in example.anchors)) for s in tokens.starts[k]]
    loss = cross_entropy(model.act_head(torch.cat(act_vectors)) * cfg.logit_scale, torch.tensor(act_labels))
    if openings_all:
        loss = loss + bce(torch.cat(openings_all), torch.tensor(boundary_labels, dtype=torch.float32))
    if split_losses:
        loss = loss + cfg.split_loss_weight * torch.stack(split_losses).mean()
    if anchor_logits:
        loss = loss + cfg.anchor_loss_weight * bce(torch.cat(anchor_logits), torch.tensor(anchor_labels))
    if variant_losses:
        loss = loss + cfg.variant_loss_weight * torch.stack(variant_losses).mean()
    return loss


def split_nll(model: ActModel, example: Example, gold: list[tuple[tuple[int, int], str]], analysis: Analysis,
              openings):
    """-log P(gold split | utterance) under the semi-CRF over every split of its segments."""
    pieces, n = example.pieces, len(example.pieces)
    spans = [(i, j) for i in range(n) for j in range(i + 1, n + 1)]
    ranges = [analysis.token_range(pieces[i].start, pieces[j - 1].end) for i, j in spans]
    span_scores = model.act_head(pooled(analysis.class_states, ranges)) * model.config.logit_scale
    acts = [(spans.index(span), CLASSES.index(label)) for span, label in gold]
    return log_partition(n, spans, span_scores, openings) - split_score(acts, spans, span_scores, openings)
