"""planner=local_context: the dialogue read with the utterance, quality (its config errors: test_local.py)."""

from __future__ import annotations

import json

import pytest

from emopose.planners.base import PlanRequest
from tests.planners.local_helpers import configured_local_planner


@pytest.fixture(scope="module")
def planner(tmp_path_factory):
    return configured_local_planner(tmp_path_factory.mktemp("lib") / "g1", "planner=local_context")


@pytest.mark.slow
def test_an_elliptical_reply_is_read_in_its_dialogue(planner):
    """The same words answer two questions two ways: the dialogue decides the class."""
    def first_class(question: str) -> str:
        history = ({"role": "assistant", "content": question},)
        raw = planner.plan(PlanRequest("Not at all.", history=history)).raw
        return json.loads(raw)["gestures"][0]["class"]

    assert first_class("Would you mind if I opened the window a little?") == "agreeing"
    assert first_class("So you found the exhibit boring, then?") == "rejecting"


@pytest.mark.slow
def test_quality_floor_on_held_out_training_slice(planner):
    from emopose.jobs.train_local import context_metrics, held_out_metrics
    from emopose.planners.local_data import load_examples

    held_out = load_examples(planner.train_files, planner.model.config.holdout_percent, held_out=True)
    utterances = [e for e in held_out if not e.history]
    metrics = held_out_metrics(planner, utterances, [planner.score(e.text) for e in utterances])
    metrics.update(context_metrics(planner, [e for e in held_out if e.history]))
    # Measured (seeded, `+experiment=train_local planner=local_context`): single top-1 86.7 %, sequence exact
    # 63.2 %, anchor recall 87.4 %, exact variant 43.2 %, dialogues 86.3 % with history, 71.1 % without.
    assert metrics["singles"] > 250 and metrics["sequences"] >= 200 and metrics["dialogues"] >= 150
    assert metrics["single_top1"] >= 0.84, metrics
    assert metrics["sequence_exact"] >= 0.59, metrics
    assert metrics["anchor_recall"] >= 0.84, metrics
    assert metrics["exact_variant"] >= 0.40, metrics
    assert metrics["context_with_history"] >= 0.83, metrics
    assert metrics["context_with_history"] >= metrics["context_without"] + 0.10, metrics


@pytest.mark.slow
def test_an_unrelated_history_barely_moves_held_out_items(planner):
    """Held-out single- and multi-act training items read after the history of a held-out dialogue that
    has nothing to do with them keep their classes and split. Measured (seeded): 86.7 % -> 82.4 % of the
    singles and 63.2 % -> 61.8 % of the multi-act items exact; a model trained with single-act
    distractors only dropped the multi-act items from 62.7 % to 29.8 % when it read them in context."""
    import random

    from emopose.planners.local_data import load_examples

    held_out = load_examples(planner.train_files, planner.model.config.holdout_percent, held_out=True)
    histories = [e.history for e in held_out if e.history]
    items = [e for e in held_out if not e.history]
    rng = random.Random(0)

    def exact(history_of) -> float:
        return sum(tuple(a.cls for a in planner.acts(e.text, history_of(e))[1])
                   == tuple(a.label for a in e.acts) for e in items) / len(items)

    alone, after = exact(lambda e: ()), exact(lambda e: rng.choice(histories))
    assert after >= alone - 0.05, (alone, after)
