"""+experiment=bench_easy|bench_medium|bench_hard|bench_all: top-1 accuracy on EmoPose-Bench.

Top-1 is the first planned class (paper protocol). Writes results.json (method, n, accuracy per tier
and overall as {mean, sd} over passes in %, predictions [{id, label, pred, tier, pass}], fallbacks,
failures, latency mean/p95), results.md (ours beside the paper) and confusion.png (one panel per tier).
"""

from __future__ import annotations

import time
from collections import Counter
from dataclasses import dataclass, field

from emopose.bench.confusion import ABBREVIATIONS, ConfusionPanel, confusion_counts, plot_confusion
from emopose.bench.metrics import accuracy, by_pass, tier_accuracy
from emopose.bench.suites import TIERS, BenchItem, load_bench
from emopose.bench.tables import comparison_markdown, fmt
from emopose.jobs.suite_planning import (
    MAX_FALLBACK_SHARE,
    check_passes,
    plan_suite,
    planner_report,
    resolve_passes,
    run_summary,
    suite_output,
)
from emopose.planners.base import PlanRequest
from emopose.resources import Resources, Run
from emopose.results import JobOutput


@dataclass
class BenchJob:
    path: str
    tiers: list[str] = field(default_factory=lambda: list(TIERS))
    passes: int | None = None  # None: 5 for a sampled planner, 1 otherwise
    chunk_size: int = 64
    progress: bool = True
    max_fallback_share: float = MAX_FALLBACK_SHARE  # above it the run is marked and exits 2
    confusion: bool = True

    def __post_init__(self) -> None:
        """The suite is loaded when the job is built: a bad value is a config error before anything starts."""
        if not self.tiers or set(self.tiers) - set(TIERS):
            raise ValueError(f"job.tiers={list(self.tiers)}: must be a non-empty subset of {list(TIERS)}")
        check_passes(self.passes)
        try:
            self.items: list[BenchItem] = load_bench(self.path, self.tiers)  # not a field, so no setting
        except OSError as exc:  # a missing or unreadable bench.path
            raise ValueError(str(exc)) from exc
        if not self.items:
            raise ValueError(f"bench.path={self.path}: no items of tiers {list(self.tiers)}")

    def __call__(self, run: Run) -> JobOutput:
        res, items = run.resources, self.items
        planner, passes = res.planner, resolve_passes(self.passes, res.planner)
        requests = [PlanRequest(utterance=i.text) for i in items]
        predictions, planned_all = [], []
        started = time.perf_counter()
        for p in range(passes):
            planned = plan_suite(planner, requests, f"{planner.name} bench pass {p + 1}/{passes}",
                                 self.chunk_size, self.progress)
            planned_all.extend(planned)
            for item, outcome in zip(items, planned):
                row = {"id": item.id, "label": item.label, "pred": outcome.top_class, "tier": item.tier,
                       "pass": p, "source": outcome.source}
                if outcome.error is not None:
                    row["error"] = outcome.error
                predictions.append(row)
        results = {
            "kind": "bench",
            "suite": str(self.path),
            "method": planner.name,
            "tiers": list(self.tiers),
            "n": len(items),
            "passes": passes,
            "accuracy": tier_accuracy(predictions, TIERS),
            "per_pass": [{t: accuracy((q["label"], q["pred"]) for q in preds if q["tier"] == t)
                          for t in self.tiers} for preds in by_pass(predictions).values()],
            **run_summary(planned_all, started, self.max_fallback_share),
            **planner_report(planner),
            "predictions": predictions,
        }
        markdown = comparison_markdown([results]) + "\n" + leading_confusions(predictions, self.tiers)
        if self.confusion:
            results["confusion_png"] = str(self.write_confusion(res, predictions, results))
            markdown += f"\nConfusion matrices: {results['confusion_png']}\n"
        return suite_output(results, markdown)

    def write_confusion(self, res: Resources, predictions: list[dict], results: dict):
        panels = []
        for tier in [t for t in TIERS if t in self.tiers]:
            pairs = [(p["label"], p["pred"]) for p in predictions if p["tier"] == tier]
            counts, failed = confusion_counts(pairs)
            title = (f"{tier.capitalize()} ({counts.sum() + failed} decisions): "
                     f"{fmt(results['accuracy'][tier])}%")
            panels.append(ConfusionPanel(title, counts, failed))
        name = f"{results['method']}, {results['passes']} pass(es), pooled counts"
        return plot_confusion(panels, res.run_dir / "confusion.png", suptitle=name)


def leading_confusions(predictions: list[dict], tiers: list[str], top: int = 5) -> str:
    """The most frequent label -> pred errors per tier, pooled over passes (as the paper discusses)."""
    lines = ["Leading confusions (annotated -> predicted, pooled count / annotated items):"]
    for tier in [t for t in TIERS if t in tiers]:
        preds = [p for p in predictions if p["tier"] == tier]
        support = Counter(p["label"] for p in preds)
        errors = Counter((p["label"], p["pred"]) for p in preds if p["pred"] != p["label"])
        shown = ", ".join(f"{ABBREVIATIONS[a]}->{ABBREVIATIONS.get(b, 'fail')} {n}/{support[a]}"
                          for (a, b), n in errors.most_common(top))
        lines.append(f"- {tier}: {shown or 'none'}")
    return "\n".join(lines) + "\n"
