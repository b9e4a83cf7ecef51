"""Training the local planner's model (planners/local/model.py) on examples from planners/local/data.py.

The frozen lower layers run once over every example (their outputs are cached in float16, with each
annotated act's pooled semantic and lexical vectors); each epoch then runs only the fine-tuned top
layers and the heads over the cache, which is what makes first-use training a few minutes on two
cores. Matrix products run in bfloat16 (autocast) where the CPU supports it natively; weights and
optimiser state stay float32; the learning rates warm up and decay linearly when lr_schedule says so.
Every pass shows a progress bar on stderr; its `left` figure is the ETA of the whole training (Remaining:
this pass and the ones after it, from the measured time per batch), not only of the pass. The losses are
planners/local/losses.py's.

The variant projections read only frozen states, so they are trained after the epochs, on the cached
act vectors, in seconds (planners/local/variant_training.py).
"""

from __future__ import annotations

import logging
import random
import sys
import time

from emopose.planners.local.data import Example
from emopose.planners.local.heads import pooled, token_range
from emopose.planners.local.losses import batch_loss
from emopose.planners.local.model import ActModel
from emopose.planners.local.variant_training import AnnotatedAct, fit_variants

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


def variant_inputs(model: ActModel, tokens, lower,
                   ranges: list[list[tuple[int, int]]]) -> list[list[tuple]]:
    """Per text, the (semantic, lexical) vectors of its token ranges: what the variant projections read."""
    semantic = model.sentence(lower, tokens.inputs["attention_mask"]).float()
    words = model.words(tokens.inputs)
    return [list(zip(pooled(semantic[k, tokens.real[k]], r), pooled(words[k, tokens.real[k]], r)))
            if r else [] for k, r in enumerate(ranges)]


def fit(model: ActModel, examples: list[Example], catalogue: dict[str, tuple[str, str]] | None = None,
        progress: bool = True) -> None:
    """Train the model's top layers and heads in place, repeatably: PyTorch's deterministic kernels are
    on for the training (two trainings otherwise differed by up to 0.02 in a weight, which moved a few
    suite items). catalogue: motion name -> (class, description)."""
    import torch

    enabled, warn_only = (torch.are_deterministic_algorithms_enabled(),
                          torch.is_deterministic_algorithms_warn_only_enabled())
    torch.use_deterministic_algorithms(True)
    try:
        train(model, examples, catalogue or {}, progress)
    finally:
        torch.use_deterministic_algorithms(enabled, warn_only=warn_only)


def train(model: ActModel, examples: list[Example], catalogue: dict[str, tuple[str, str]],
          progress: bool) -> None:
    import torch

    cfg = model.config
    torch.manual_seed(cfg.seed)
    rng = random.Random(cfg.seed)
    top = unfreeze_top(model)
    model.learn_words(sorted({e.text for e in examples}))
    model.annotated_motions = sorted({v for e in examples for v in e.variants if v})
    # The projections learn among the annotated motions only: any other motion of the live library (a
    # user's, a test's copy) would become a negative and change the artifact, which the training files
    # and config alone key (a test that trained on first use gave the shipped model 48 % exact variants)
    catalogue = {name: entry for name, entry in catalogue.items() if name in model.annotated_motions}
    bf16 = torch.ops.mkldnn._is_mkldnn_bf16_supported()
    batches = length_batches(model, examples)
    remaining = Remaining(len(batches), cfg.epochs * len(batches), cfg.trainable_layers)
    cache, annotated = frozen_passes(model, batches, catalogue, bf16, progress, remaining)
    fit_top(model, top, cache, len(examples), rng, bf16, progress, remaining)
    fit_variants(model.variant_projections, annotated, describe(model, catalogue), cfg, progress)


def unfreeze_top(model: ActModel):
    """Freeze the encoder but its top layers (cfg.trainable_layers), whose dropout becomes cfg.dropout;
    those are returned."""
    import torch

    for p in model.body.parameters():
        p.requires_grad_(False)
    top = model.body.encoder.layer[model.frozen_depth:]
    for p in top.parameters():
        p.requires_grad_(True)
    for module in top.modules():
        if isinstance(module, torch.nn.Dropout):  # the eager attention reads its probability from here too
            module.p = model.config.dropout
    return top


def length_batches(model: ActModel, examples: list[Example]) -> list[list[Example]]:
    """Batches of inputs with the same token count (history prefix included) are barely padded (sorting
    by the utterance's characters left a third of every batch padding); fit_top shuffles their order."""
    lengths = model.input_lengths([e.text for e in examples], [e.history for e in examples])
    by_length = [examples[k] for k in sorted(range(len(examples)), key=lengths.__getitem__)]
    size = model.config.batch_size
    return [by_length[k:k + size] for k in range(0, len(by_length), size)]


class Remaining:
    """The whole training's time left: frozen batches at their measured pace, epoch batches at theirs
    (before the first is measured: EPOCH_COST_PER_LAYER times a frozen batch's per fine-tuned layer; the
    frozen pass costs about the same whatever its depth, tokenising included. Measured on an idle 2-core
    machine with two threads, 2026-12-05: 0.021 s a frozen batch, 0.13 s an epoch batch with five
    fine-tuned layers without dropout, 0.16 s with it)."""

    EPOCH_COST_PER_LAYER = 1.25

    def __init__(self, frozen: int, epoch: int, trainable_layers: int) -> None:
        self.epoch_cost = self.EPOCH_COST_PER_LAYER * trainable_layers
        self.left = {"frozen": frozen, "epoch": epoch}
        self.spent = {"frozen": 0.0, "epoch": 0.0}
        self.done = {"frozen": 0, "epoch": 0}
        self._since = time.perf_counter()

    def step(self, kind: str) -> str:
        """Count one batch of `kind` as done; the time left, as m:ss."""
        now = time.perf_counter()
        self.spent[kind] += now - self._since
        self._since = now
        self.done[kind] += 1
        self.left[kind] -= 1
        pace = {k: self.spent[k] / self.done[k] for k in self.done if self.done[k]}
        frozen = pace.get("frozen", 0.0)
        epoch = pace.get("epoch", self.epoch_cost * frozen)
        seconds = round(self.left["frozen"] * frozen + self.left["epoch"] * epoch)
        return f"{seconds // 60}:{seconds % 60:02d}"

    def restart(self) -> None:
        """Do not count time between passes (the variant pass, the optimiser's setup) as a batch's."""
        self._since = time.perf_counter()


def frozen_passes(model: ActModel, batches: list[list[Example]], catalogue: dict[str, tuple[str, str]],
                  bf16: bool, progress: bool, remaining: Remaining) -> tuple[list[tuple], list[AnnotatedAct]]:
    """One pass of the frozen layers over every batch: (batch, tokens, float16 states) per batch, and
    the annotated acts' vectors for the variant projections."""
    import torch
    from tqdm import tqdm

    cache, annotated = [], []
    with torch.no_grad(), torch.autocast("cpu", dtype=torch.bfloat16, enabled=bf16):
        bar = tqdm(batches, desc="local planner: frozen layers", unit="batch", file=sys.stderr,
                   disable=not progress)
        remaining.restart()
        for batch in bar:
            tokens = model.tokens([e.text for e in batch], [e.history for e in batch])
            lower = model.lower(tokens.inputs)
            if catalogue and any(e.variants for e in batch):  # the pretrained top and the words: variants
                annotated += annotated_acts(model, batch, tokens, lower)
            cache.append((batch, tokens, lower.half()))
            bar.set_postfix(all_left=remaining.step("frozen"), refresh=False)
    return cache, annotated


def fit_top(model: ActModel, top, cache: list[tuple], examples: int, rng: random.Random, bf16: bool,
            progress: bool, remaining: Remaining) -> None:
    """The epochs over the cached frozen states: the top layers and the heads (examples: how many)."""
    import torch
    from tqdm import tqdm

    cfg = model.config
    heads = [q for h in (model.act_head, model.boundary_head, model.anchor_head, model.relevance_head,
                         model.onset_head) for q in h.parameters()]
    # fused: one kernel a step, not one a tensor, the same update rule (0.106 s a batch against 0.122 in an
    # interleaved comparison on 40 batches with five layers)
    optimizer = torch.optim.AdamW([{"params": list(top.parameters()), "lr": cfg.lr},
                                   {"params": heads, "lr": cfg.head_lr}], weight_decay=0.01, fused=True)
    steps = cfg.epochs * len(cache)
    scheduler = torch.optim.lr_scheduler.LambdaLR(optimizer, learning_rate_factor(cfg, steps))
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
            remaining.restart()
            for batch, tokens, lower in bar:
                with torch.autocast("cpu", dtype=torch.bfloat16, enabled=bf16):
                    loss = batch_loss(model, batch, tokens, lower.float())
                optimizer.zero_grad()
                loss.backward()
                optimizer.step()
                scheduler.step()
                total += loss.item() * len(batch)
                bar.set_postfix(loss=f"{loss.item():.3f}", all_left=remaining.step("epoch"), refresh=False)
            log.info("local planner epoch %d/%d: loss %.4f", epoch + 1, cfg.epochs, total / examples)
    finally:
        model.body.set_attn_implementation(attention)
    top.eval()


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
