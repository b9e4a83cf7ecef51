"""The local planner's triggers: the words each gesture belongs to, and its bad input (slow: the model)."""

from __future__ import annotations

import json

import pytest

from emopose.contract import trigger_position
from emopose.planners.base import PlanRequest
from emopose.stages.parse import parse_plan
from tests.planners.local_helpers import configured_local_planner


@pytest.fixture(scope="module")
def planner(tmp_path_factory):
    return configured_local_planner(tmp_path_factory.mktemp("lib") / "g1")


def records(planner, text: str) -> list[dict]:
    return json.loads(planner.plan(PlanRequest(text)).raw)["gestures"]


@pytest.mark.slow
def test_a_pointing_trigger_starts_at_the_place_not_at_the_clause(planner):
    # the anchor head marks the clause ("The planetarium is up those stairs"); planners/local/affiliate.py
    # moves the start onto the place
    gestures = records(planner, "The planetarium is up those stairs, and the cafe is behind the gift shop.")
    pointing = [g["trigger"] for g in gestures if g["class"] == "pointing"]
    assert pointing and pointing[0].lower().startswith("up")


@pytest.mark.slow
def test_the_place_s_direction_picks_the_motion_even_from_a_clause_long_trigger(planner):
    gestures = records(planner, "The planetarium is up those stairs, and the cafe is behind the gift shop.")
    assert gestures[0]["class"] == "pointing" and gestures[0]["variant"] == "point_up"


@pytest.mark.slow
def test_direction_words_pick_the_motion_that_points_that_way(planner):
    left = records(planner, "Over there on the left you can see the old printing press.")
    assert left[0]["class"] == "pointing" and left[0]["variant"] == "point_left"
    up = records(planner, "The bats roost way up in the rafters.")
    assert up[0]["class"] == "pointing" and up[0]["variant"] == "point_up"


@pytest.mark.slow
def test_a_one_word_reply_gets_one_record_on_that_word(planner):
    gestures = records(planner, "Welcome!")
    assert len(gestures) == 1 and gestures[0]["trigger"] == "Welcome"


@pytest.mark.slow
def test_forty_gestures_worth_of_text_plans_the_first_acts_with_triggers_in_order(planner):
    sentences = ["Welcome in.", "The cloakroom is on your left.", "No, please don't touch the glass.",
                 "I'm not sure the lift works today.", "Yes, the tour is free."] * 8
    text = " ".join(sentences)
    gestures = records(planner, text)
    assert 1 <= len(gestures) <= planner.settings.max_records
    positions = [trigger_position(text, g["trigger"]) for g in gestures]
    assert None not in positions and positions == sorted(positions)
    plan = parse_plan(planner.plan(PlanRequest(text)).raw, text)  # the parser keeps the first 200 chars
    assert all(trigger_position(plan.reply, r.trigger) is not None for r in plan.records)
