"""Python's garbage collector in real-time runs: its pauses stop every thread of the process, the loop's too.

A full collection walks every tracked object. A served process (torch, the sentence model, Hydra, MuJoCo,
the web app) holds 70,000+ of them once set up, and one full pass over them took 143 ms here: a gap in the
50 Hz command stream that no thread priority prevents (and, on the G1, longer than half the 100 ms
deadman). So a real-time run collects once and freezes what survives set-up (gc.freeze: those objects are
never scanned again) before it connects the robot (Session.open) and again before the loop's thread starts
(ControlLoop.start), leaving the collector only what the session allocates; and the loop's thread times
every pause, so loop health shows them."""

from __future__ import annotations

import gc
import time


def freeze_survivors() -> None:
    """Collect, then exempt every surviving object from later collections (call once set-up is done,
    before the loop runs: the collection itself is the long pause being avoided)."""
    gc.collect()
    gc.freeze()


class CollectorPauses:
    """Counts collections and times them (gc.callbacks run on the collecting thread, under the GIL)."""

    def __init__(self) -> None:
        self.collections = 0
        self.full_collections = 0
        self.longest_s = 0.0
        self._started = 0.0

    def install(self) -> None:
        if self._on_gc not in gc.callbacks:
            gc.callbacks.append(self._on_gc)

    def remove(self) -> None:
        if self._on_gc in gc.callbacks:
            gc.callbacks.remove(self._on_gc)

    def _on_gc(self, phase: str, info: dict) -> None:
        if phase == "start":
            self._started = time.perf_counter()
            return
        self.collections += 1
        self.full_collections += info["generation"] == 2
        self.longest_s = max(self.longest_s, time.perf_counter() - self._started)

    def summary(self) -> dict:
        return {"gc_collections": self.collections, "gc_full_collections": self.full_collections,
                "gc_pause_ms_max": round(self.longest_s * 1e3, 2)}
