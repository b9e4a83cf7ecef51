"""Every benchmark experiment end to end (compose -> build -> job -> results files) on small fixtures."""

import json
import math
from pathlib import Path
from types import SimpleNamespace

import pytest

from emopose.bench.suites import SuiteError
from emopose.build import ConfigError
from emopose.jobs.bench import BenchJob
from emopose.planners.base import PlannerFailure, PlannerOutput
from emopose.planners.baselines.keyword import KeywordPlanner
from emopose.results import JobFailure

FIXTURES = Path(__file__).parent / "fixtures"
BENCH = f"bench.path={FIXTURES / 'bench_small.jsonl'}"


@pytest.mark.parametrize("experiment,tier", [("bench_easy", "easy"), ("bench_medium", "medium"),
                                             ("bench_hard", "hard")])
def test_single_tier_experiments(run_experiment, experiment, tier):
    results, run_dir = run_experiment(experiment, BENCH)
    assert results["n"] == 8 and results["passes"] == 1 and results["tiers"] == [tier]
    assert {p["tier"] for p in results["predictions"]} == {tier}
    assert results["accuracy"][tier]["mean"] == results["accuracy"]["overall"]["mean"]
    others = [t for t in ("easy", "medium", "hard") if t != tier]
    assert all(results["accuracy"][t] is None for t in others)
    assert (run_dir / "confusion.png").is_file()


def test_bench_all_results_file(run_experiment):
    _, run_dir = run_experiment("bench_all", BENCH)
    saved = json.loads((run_dir / "results.json").read_text())
    assert saved["method"] == "keyword" and saved["n"] == 24 and saved["kind"] == "bench"
    assert set(saved["accuracy"]) == {"easy", "medium", "hard", "overall"}
    assert all(set(v) == {"mean", "sd"} for v in saved["accuracy"].values())
    assert saved["accuracy"]["overall"]["sd"] is None  # one pass: no spread
    assert set(saved["predictions"][0]) >= {"id", "label", "pred", "tier", "pass"}
    correct = sum(p["pred"] == p["label"] for p in saved["predictions"])
    assert math.isclose(saved["accuracy"]["overall"]["mean"], 100 * correct / 24)
    assert saved["fallbacks"] == 0 and saved["failures"] == 0
    assert saved["latency_s"]["mean"] >= 0 and saved["latency_s"]["p95"] >= 0
    md = (run_dir / "results.md").read_text()
    assert "keyword" in md and "(30.21)" in md  # the paper's overall keyword accuracy beside ours


def test_passes_override_and_seeded_chance(run_experiment):
    results, _ = run_experiment("bench_all", BENCH, "passes=3", "job.confusion=false", planner="chance")
    assert results["passes"] == 3 and len(results["predictions"]) == 72
    assert results["accuracy"]["overall"]["sd"] is not None
    again, _ = run_experiment("bench_all", BENCH, "passes=3", "job.confusion=false", planner="chance")
    assert again["predictions"] == results["predictions"]  # same run.seed, same draws


def test_context_ablation(run_experiment):
    results, run_dir = run_experiment("context_ablation", f"bench.path={FIXTURES / 'context_small.jsonl'}")
    assert results["kind"] == "context_ablation" and results["n"] == 8
    acc = results["accuracy"]
    assert acc["gain"]["mean"] == acc["with_history"]["mean"] - acc["without_history"]["mean"]
    assert {"pred_with", "pred_without"} <= set(results["predictions"][0])
    assert (run_dir / "results.md").is_file()


def test_sequence_suite(run_experiment):
    results, _ = run_experiment("sequence_suite", f"bench.path={FIXTURES / 'sequence_small.jsonl'}")
    m = results["metrics"]
    assert results["kind"] == "sequence_suite" and results["n"] == 6
    assert set(m) >= {"primary_class", "ordered_exact", "aligned_step", "multiset_f1", "anchor_recall",
                      "exact_variant", "exact_len2", "exact_len3", "exact_len4"}
    assert m["exact_variant"]["mean"] == 0.0  # keyword names no variants
    assert m["anchor_recall"]["mean"] > 0     # keyword triggers are the cue words themselves
    assert set(results["segmentation"]) >= {"over_total", "under_total", "failed_total"}
    onsets = results["anchor_onsets"]  # espeak timings: where the triggers start against the gold anchors
    assert onsets["anchors"] == 18 and 0 <= onsets["within"] <= onsets["with_gesture"] <= 18


def test_sequence_suite_refuses_variants_missing_from_the_library(run_experiment, tmp_path):
    bad = tmp_path / "seq.jsonl"
    bad.write_text(json.dumps({"id": "s1", "text": "Hello! Over there.", "labels": ["welcoming", "pointing"],
                               "anchors": ["Hello", "Over there"],
                               "variants": ["welcoming_a", "point_left"]}) + "\n")
    with pytest.raises(SuiteError, match=r"seq.jsonl:1: field 'variants\[1\]'"):
        run_experiment("sequence_suite", f"bench.path={bad}")


def test_malformed_suite_is_refused_with_file_line_field(run_experiment, tmp_path):
    bad = tmp_path / "bench.jsonl"
    good = (FIXTURES / "bench_small.jsonl").read_text().splitlines()
    bad.write_text("\n".join(good[:3] + [good[3].replace('"tier": "easy"', '"tier": "extreme"')]) + "\n")
    with pytest.raises(ConfigError, match=r"bench.jsonl:4: field 'tier': unknown value 'extreme'"):
        run_experiment("bench_all", f"bench.path={bad}")  # refused when the job is built: one line, exit 2


class FlakyPlanner(KeywordPlanner):
    """Raises on utterances containing 'boom'; has plan_many, so whole chunks fail first."""

    name = "flaky"

    def plan(self, request):
        if "boom" in request.utterance:
            raise RuntimeError("model exploded")
        return super().plan(request)

    def plan_many(self, requests):
        return [self.plan(r) for r in requests]


def planning_run(planner, tmp_path):
    """What a planning-only job reads of a Run: the planner and the run directory."""
    return SimpleNamespace(resources=SimpleNamespace(planner=planner, run_dir=tmp_path / "run"))


def test_a_failing_item_is_recorded_and_the_run_continues(tmp_path):
    suite = tmp_path / "bench.jsonl"
    rows = [{"id": "a", "text": "Yes, exactly.", "label": "agreeing", "tier": "easy"},
            {"id": "b", "text": "boom goes the item", "label": "neutral", "tier": "easy"},
            {"id": "c", "text": "No, never.", "label": "rejecting", "tier": "easy"}]
    suite.write_text("".join(json.dumps(r) + "\n" for r in rows))
    run = planning_run(FlakyPlanner(), tmp_path)
    results, markdown = BenchJob(path=str(suite), progress=False, confusion=False)(run)
    preds = {p["id"]: p for p in results["predictions"]}
    assert preds["b"]["pred"] is None and "model exploded" in preds["b"]["error"]
    assert preds["a"]["pred"] == "agreeing" and preds["c"]["pred"] == "rejecting"
    assert results["failures"] == 1 and results["accuracy"]["overall"]["mean"] == pytest.approx(200 / 3)
    assert "flaky" in markdown  # the comparison table app.run writes to results.md and prints


def test_sampled_planner_defaults_to_five_passes(tmp_path):
    class Sampled(KeywordPlanner):
        sampled = True

    suite = FIXTURES / "bench_small.jsonl"
    run = planning_run(Sampled(), tmp_path)
    results, _ = BenchJob(path=str(suite), tiers=["easy"], progress=False, confusion=False)(run)
    assert results["passes"] == 5 and len(results["predictions"]) == 40
    assert results["accuracy"]["easy"]["sd"] == 0.0


class Garbled(KeywordPlanner):
    """Every answer is unusable (an intensity that is not a level), so every plan is a fallback."""

    def plan(self, request):
        return PlannerOutput(raw='{"gestures": [{"class": "agreeing", "intensity": "loud"}]}')


def test_fallback_outputs_are_counted(tmp_path):
    run = planning_run(Garbled(), tmp_path)
    results, _ = BenchJob(path=str(FIXTURES / "bench_small.jsonl"), tiers=["easy"], progress=False,
                          confusion=False, max_fallback_share=1.0)(run)  # 1.0: counted, not failed
    assert results["fallbacks"] == 8 and results["failures"] == 0


def test_too_many_fallbacks_fail_with_the_results_to_write(tmp_path):
    run = planning_run(Garbled(), tmp_path)
    job = BenchJob(path=str(FIXTURES / "bench_small.jsonl"), tiers=["easy"], progress=False, confusion=False,
                   max_fallback_share=0.5)
    with pytest.raises(JobFailure) as failed:
        job(run)
    assert failed.value.results["fallback_exceeded"] and failed.value.results["fallbacks"] == 8
    assert "keyword" in failed.value.markdown  # the table app.run writes and prints before failing
    assert isinstance(failed.value.error, PlannerFailure)
    assert "fell back on 8 answers (100.0 % > job.max_fallback_share 50 %" in str(failed.value.error)
