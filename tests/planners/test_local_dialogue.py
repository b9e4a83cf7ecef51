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


def unrelated_histories(planner):
    """Held-out items without history, each with the history of a held-out dialogue (seeded draw)."""
    import random

    from emopose.jobs.train_local import held_out_examples

    held_out = held_out_examples(planner)
    histories = [e.history for e in held_out if e.history]
    rng = random.Random(0)
    return [(e, rng.choice(histories)) for e in held_out if not e.history], [e for e in held_out if e.history]


@pytest.mark.slow
def test_an_unrelated_history_barely_moves_held_out_items(planner):
    """Held-out single- and multi-act training items read after the history of a held-out dialogue that
    has nothing to do with them keep their classes and split. Measured (seeded): singles 87.8 % alone,
    83.9 % after (81.0 % with the history always read), multi-act items 65.4 % alone, 63.6 % after
    (61.0 %); before the relevance head 87.1 -> 81.4 and 62.7 -> 61.0; a model trained with single-act
    distractors only dropped the multi-act items from 62.7 % to 29.8 % when it read them in context."""
    items, _ = unrelated_histories(planner)

    def exact(with_history: bool) -> float:
        return sum(tuple(a.cls for a in planner.acts(e.text, history if with_history else ())[1])
                   == tuple(a.label for a in e.acts) for e, history in items) / len(items)

    alone, after = exact(False), exact(True)
    assert after >= alone - 0.03, (alone, after)


@pytest.mark.slow
def test_a_history_that_does_not_bear_on_the_utterance_is_dropped(planner):
    """The relevance head tells a dialogue's own history from another dialogue's. Measured at its own
    boundary, logit 0: 94.8 % of the held-out dialogues' own histories judged relevant, 84.8 % when the
    same replies follow another dialogue's history (an elliptical reply fits many questions), 30.0 % for
    items written without a dialogue (16.8 % when trained in batches of 32: the boundary moved, the
    configured threshold still drops 58 % of them). Below that threshold the planner reads the utterance
    alone."""
    items, dialogues = unrelated_histories(planner)
    model = planner.model

    def relevance(text, history) -> float:
        return model.analyse([text], [history])[0].relevance_logit

    own = [relevance(e.text, e.history) for e in dialogues]
    others = [relevance(e.text, dialogues[(k + 1) % len(dialogues)].history) for k, e in enumerate(dialogues)]
    judged = [(e, history, relevance(e.text, history)) for e, history in items[:120]]
    own_rate = sum(r >= 0 for r in own) / len(own)
    assert own_rate >= 0.85 and sum(r >= 0 for r in others) / len(others) <= own_rate - 0.05, own_rate
    assert sum(r >= 0 for *_, r in judged) / len(judged) <= 0.35
    assert model.analyse(["Over there."])[0].relevance_logit is None  # no history, nothing to judge
    dropped = [(e, history) for e, history, r in judged if r < planner.settings.history_threshold]
    assert len(dropped) >= 0.4 * len(judged)
    for e, history in dropped:
        assert [(a.cls, a.start, a.end) for a in planner.acts(e.text, history)[1]] == \
            [(a.cls, a.start, a.end) for a in planner.acts(e.text)[1]]
