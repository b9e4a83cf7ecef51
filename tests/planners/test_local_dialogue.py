"""The local planner reads the dialogue with the utterance (quality floors: test_local.py)."""

from __future__ import annotations

import json

import pytest

from emopose.planners.base import PlanRequest
from tests.planners.local_helpers import configured_local_planner


@pytest.fixture(scope="module")
def planner(tmp_path_factory):
    return configured_local_planner(tmp_path_factory.mktemp("lib") / "g1")


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
def test_an_unrelated_history_barely_moves_held_out_items(planner):
    """Held-out single- and multi-act training items read after the history of a held-out dialogue that
    has nothing to do with them keep their classes and split. Measured (seeded): 87.8 % -> 82.1 % of the
    singles and 61.8 % -> 59.2 % of the multi-act items exact (with 800 unrelated histories in training
    instead of 1,200: 87.1 -> 79.6 and 64.0 -> 59.2); a model trained with single-act distractors only
    dropped the multi-act items from 62.7 % to 29.8 % when it read them in context."""
    import random

    from emopose.planners.local_data import load_examples

    held_out = load_examples(planner.train_files, planner.config.holdout_percent, held_out=True)
    histories = [e.history for e in held_out if e.history]
    items = [e for e in held_out if not e.history]
    rng = random.Random(0)

    def exact(history_of) -> float:
        return sum(tuple(a.cls for a in planner.acts(e.text, history_of(e))[1])
                   == tuple(a.label for a in e.acts) for e in items) / len(items)

    alone, after = exact(lambda e: ()), exact(lambda e: rng.choice(histories))
    assert after >= alone - 0.05, (alone, after)
