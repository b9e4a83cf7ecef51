"""+experiment=context_ablation: paired dialogue-history ablation on the context suite.

Every item is planned twice per pass with the same planner: with its preceding dialogue turns and with
them removed. Accuracy (%) with and without history and the paired gain are computed per pass and
reported as mean and sample SD over passes (paper Table extensions), with pooled discordant pairs.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from emopose.bench.metrics import paired_context_accuracy
from emopose.bench.suites import ContextItem, load_context
from emopose.bench.tables import comparison_markdown
from emopose.jobs.suite_planning import (
    MAX_FALLBACK_SHARE,
    check_passes,
    load_suite,
    plan_suite,
    resolve_passes,
    run_summary,
    suite_output,
)
from emopose.planners.base import PlanRequest
from emopose.resources import Run
from emopose.results import JobOutput


@dataclass
class ContextAblationJob:
    path: str
    passes: int | None = None  # None: 5 for a sampled planner, 1 otherwise
    chunk_size: int = 64
    progress: bool = True
    max_fallback_share: float = MAX_FALLBACK_SHARE  # above it the run is marked and exits 2

    def __post_init__(self) -> None:
        """The suite is read when the job is built: a bad value is a config error before anything starts."""
        check_passes(self.passes)
        self.items: list[ContextItem] = load_suite(load_context, self.path)  # not a field, so no setting

    def __call__(self, run: Run) -> JobOutput:
        res, items = run.resources, self.items
        planner, passes = res.planner, resolve_passes(self.passes, res.planner)
        with_history = [PlanRequest(utterance=i.text, history=i.history) for i in items]
        without_history = [PlanRequest(utterance=i.text) for i in items]
        predictions, planned_all = [], []
        started = time.perf_counter()
        for p in range(passes):
            tag = f"{planner.name} context pass {p + 1}/{passes}"
            planned_with = plan_suite(planner, with_history, f"{tag} with history", self.chunk_size,
                                      self.progress)
            planned_without = plan_suite(planner, without_history, f"{tag} without", self.chunk_size,
                                         self.progress)
            planned_all += planned_with + planned_without
            for item, a, b in zip(items, planned_with, planned_without):
                predictions.append({"id": item.id, "label": item.label, "pred_with": a.top_class,
                                    "pred_without": b.top_class, "history_turns": len(item.history),
                                    "pass": p, "source_with": a.source, "source_without": b.source})
        paired = paired_context_accuracy(predictions)
        results = {
            "kind": "context_ablation",
            "suite": str(self.path),
            "method": planner.name,
            "n": len(items),
            "passes": passes,
            "accuracy": {k: paired[k] for k in ("with_history", "without_history", "gain")},
            "per_pass": paired["per_pass"],
            "discordant": paired["discordant"],
            **run_summary(planned_all, started, self.max_fallback_share),
            "predictions": predictions,
        }
        d = paired["discordant"]
        markdown = comparison_markdown([results]) + (
            f"\nDiscordant pairs (pooled over passes): right only with history {d['only_with_history']}, "
            f"right only without {d['only_without_history']}.\n")
        return suite_output(results, markdown)
