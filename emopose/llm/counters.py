"""Counters shared by an LLM client and its planner: calls, cache hits, retries, fallbacks, latency.

Latency is split in two, because a benchmark with `concurrency: 16` against a one-slot local server
spends most of its time waiting: `latencies_s` is time on the wire (the server's time, retries and
backoff included) and `queue_s` is time a request waited for a concurrency slot before it was sent.
`prompt_tokens` is each answered request's prompt size as the server counted it (its `usage`; a
server that sends none leaves it empty). Thread-safe because the web UI plans from threads.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field

import numpy as np


def _mean_p95(values: list[float]) -> tuple[float | None, float | None]:
    arr = np.asarray(values, dtype=float)
    return (float(arr.mean()), float(np.percentile(arr, 95))) if arr.size else (None, None)


def _token_range(values: list[int]) -> dict | None:
    """min / mean / max of the server-counted prompt sizes; None when the server reported none."""
    if not values:
        return None
    return {"min": min(values), "mean": sum(values) / len(values), "max": max(values),
            "counted_by": "server usage"}


@dataclass
class CallCounters:
    calls: int = 0
    cache_hits: int = 0
    retries: int = 0
    failed_calls: int = 0  # calls that failed for good (the planner answers with keyword rules)
    latencies_s: list[float] = field(default_factory=list)  # model calls only; a cache hit is not inference
    queue_s: list[float] = field(default_factory=list)  # waits for a concurrency slot, one per model call
    prompt_tokens: list[int] = field(default_factory=list)  # the server's usage.prompt_tokens per answer
    _lock: threading.Lock = field(default_factory=threading.Lock, repr=False)

    def add(self, **counts: int) -> None:
        with self._lock:
            for name, n in counts.items():
                setattr(self, name, getattr(self, name) + n)

    def latency(self, seconds: float, queued_s: float = 0.0) -> None:
        with self._lock:
            self.latencies_s.append(seconds)
            self.queue_s.append(queued_s)

    def prompt(self, tokens: int | None) -> None:
        if tokens is not None:
            with self._lock:
                self.prompt_tokens.append(tokens)

    def stats(self) -> dict:
        with self._lock:
            latency, queue = _mean_p95(self.latencies_s), _mean_p95(self.queue_s)
            return {"calls": self.calls, "cache_hits": self.cache_hits, "retries": self.retries,
                    "failed_calls": self.failed_calls, "model_calls": len(self.latencies_s),
                    "latency_mean_s": latency[0], "latency_p95_s": latency[1],
                    "queue_mean_s": queue[0], "queue_p95_s": queue[1],
                    "prompt_tokens": _token_range(self.prompt_tokens)}
