"""+experiment=sequence_suite: ordered multi-action planning on the sequence suite.

Each item's planned records (class, trigger, variant, in order) are scored against the annotated
labels, anchors and variants with emopose.bench.sequence_metrics (definitions there). Rates are per
pass, reported as mean and sample SD over passes; segmentation counts are pooled over passes.
Annotated variants are checked against the live library before planning (check_variants).
With tts=espeak (the experiment's default) it also reports where the triggers start against the gold
anchors in speech time (emopose.sync.affiliate): the share of anchors whose gesture's trigger onset is
within 200 ms of the anchor's, and the signed offsets, pooled over passes.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from emopose.bench.metrics import aggregate_passes
from emopose.bench.sequence_metrics import SequencePrediction, suite_scores
from emopose.bench.suites import SequenceItem, load_sequence
from emopose.bench.tables import comparison_markdown
from emopose.jobs.suite_planning import (
    MAX_FALLBACK_SHARE,
    PlannedItem,
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
from emopose.speech.espeak import EspeakSynthesizer
from emopose.sync.affiliate import anchor_offsets, offset_summary

COUNT_KEYS = ("over", "under", "failed")


def as_prediction(outcome: PlannedItem) -> SequencePrediction:
    if outcome.plan is None:
        return SequencePrediction(classes=None)
    records = outcome.plan.records
    return SequencePrediction(tuple(r.cls for r in records), tuple(r.trigger for r in records),
                              tuple(r.variant for r in records))


@dataclass
class SequenceSuiteJob:
    path: str
    passes: int | None = None  # None: 5 for a sampled planner, 1 otherwise
    check_variants: bool = True
    chunk_size: int = 64
    progress: bool = True
    max_fallback_share: float = MAX_FALLBACK_SHARE  # above it the run is marked and exits 2

    def __post_init__(self) -> None:
        """The suite is read when the job is built: a bad value is a config error before anything starts."""
        check_passes(self.passes)
        self.items: list[SequenceItem] = load_suite(load_sequence, self.path)  # not a field, so no setting

    def __call__(self, run: Run) -> JobOutput:
        res, items = run.resources, self.items
        if self.check_variants:  # the library exists only now: read again, a SuiteError names the line
            entries = res.library.snapshot.entries
            items = load_sequence(self.path, {name: e.cls for name, e in entries.items()})
        planner, passes = res.planner, resolve_passes(self.passes, res.planner)
        requests = [PlanRequest(utterance=i.text) for i in items]
        per_pass, predictions, planned_all = [], [], []
        started = time.perf_counter()
        offsets: list[float | None] = []
        for p in range(passes):
            planned = plan_suite(planner, requests, f"{planner.name} sequence pass {p + 1}/{passes}",
                                 self.chunk_size, self.progress)
            planned_all.extend(planned)
            preds = [as_prediction(o) for o in planned]
            if isinstance(res.synthesizer, EspeakSynthesizer):
                offsets += [o for item, pred in zip(items, preds)
                            for o in anchor_offsets(item.text, item.spans, pred.triggers,
                                                    res.synthesizer.word_events(item.text))]
            per_pass.append(suite_scores(items, preds))
            for item, pred, outcome in zip(items, preds, planned):
                predictions.append({"id": item.id, "labels": list(item.labels),
                                    "pred": None if pred.classes is None else list(pred.classes),
                                    "triggers": list(pred.triggers),
                                    "variants": list(pred.variants), "pass": p, "source": outcome.source})
        rates = [{k: v for k, v in scores.items() if k not in COUNT_KEYS} for scores in per_pass]
        results = {
            "kind": "sequence_suite",
            "suite": str(self.path),
            "method": planner.name,
            "n": len(items),
            "passes": passes,
            "metrics": aggregate_passes(rates),
            "segmentation": {f"{k}_total": sum(s[k] for s in per_pass) for k in COUNT_KEYS}
            | {f"{k}_per_pass": [s[k] for s in per_pass] for k in COUNT_KEYS},
            "per_pass": per_pass,
            "anchor_onsets": offset_summary(offsets) if offsets else None,
            **run_summary(planned_all, started, self.max_fallback_share),
            "predictions": predictions,
        }
        seg = results["segmentation"]
        markdown = comparison_markdown([results]) + (
            f"\nPooled over {passes} pass(es) x {len(items)} plans: {seg['over_total']} over-segmented, "
            f"{seg['under_total']} under-segmented, {seg['failed_total']} failed.\n"
            + onset_markdown(results["anchor_onsets"]))
        return suite_output(results, markdown)


def onset_markdown(summary: dict | None) -> str:
    """The trigger-onset figure in a sentence (none without espeak word timings)."""
    if summary is None or not summary["with_gesture"]:
        return "\nTrigger onsets against the gold anchors: not measured (needs tts=espeak and triggers).\n"
    return (f"\nTrigger onset within {summary['window_ms']:.0f} ms of the gold anchor's onset (espeak): "
            f"{summary['within']}/{summary['anchors']} anchors ({100 * summary['within_share']:.1f} %); "
            f"signed offset p5 / median / p95 {summary['p5_ms']:.0f} / {summary['p50_ms']:.0f} / "
            f"{summary['p95_ms']:.0f} ms, {100 * summary['early_share']:.1f} % earlier and "
            f"{100 * summary['late_share']:.1f} % later than the window, "
            f"{summary['anchors'] - summary['with_gesture']} without a gesture.\n")
