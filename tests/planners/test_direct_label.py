"""planner=direct_label end to end through the fake server: one label in, one contract record out."""

from __future__ import annotations

import json

import pytest
from fake_answers import http_error, ok

from emopose.planners.base import PlanRequest
from emopose.planners.chat.direct_label import label_from_answer
from emopose.stages.parse import parse_output, parse_plan

LINE = PlanRequest("It's alright, these things happen to everyone.",
                   history=({"role": "user", "content": "I broke the vase."},))


@pytest.mark.parametrize("answer,label", [("comforting", "comforting"), ("Comforting.", "comforting"),
                                          ("Label: agreeing", "agreeing"), ("banana", None), ("", None)])
def test_label_from_answer(answer, label):
    assert label_from_answer(answer) == label


def test_label_becomes_one_contract_record(fake_openai, make_label_planner):
    fake_openai.default = ok("Comforting")
    out = make_label_planner().plan(LINE)
    assert not out.fallback
    data = json.loads(out.raw)
    assert data["reply"] == LINE.utterance
    assert data["gestures"] == [{"class": "comforting", "variant": None, "intensity": 3, "trigger": None,
                                 "confidence": 1.0}]
    plan = parse_plan(out.raw, LINE.utterance)
    assert plan.source == "model" and [r.cls for r in plan.records] == ["comforting"]


def test_an_answer_without_a_label_is_a_counted_fallback(fake_openai, make_label_planner):
    fake_openai.default = ok("I would say it is mostly kind.")
    plan = parse_output(make_label_planner().plan(LINE), LINE.utterance)
    assert plan.source == "plain_text" and plan.fallback  # not a silent neutral with confidence 0
    assert [r.cls for r in plan.records] == ["neutral"] and plan.reply == LINE.utterance  # the line is kept


def test_same_data_different_question(fake_openai, make_label_planner):
    fake_openai.default = ok("comforting")
    make_label_planner().plan(LINE)
    messages = fake_openai.requests[0]["messages"]
    system = messages[0]["content"]
    assert "- comforting: consoles or reassures" in system  # class definitions
    assert "Answer: comforting" in system and "Example 5" in system  # demonstrations, as labels
    assert "Motion library" not in system and "comforting_a" not in system  # no guide, no schema
    assert [m["role"] for m in messages] == ["system", "user", "user"]  # the history is kept


def test_shares_the_retry_and_fallback_path(fake_openai, make_label_planner):
    fake_openai.script(http_error(500), ok("rejecting"))
    planner = make_label_planner()
    assert json.loads(planner.plan(LINE).raw)["gestures"][0]["class"] == "rejecting"
    fake_openai.default = http_error(500)
    out = planner.plan(PlanRequest("No, absolutely not."))
    assert out.fallback and parse_plan(out.raw).records[0].cls == "rejecting"
    assert planner.stats()["retries"] == 1 + 3 and planner.stats()["failed_calls"] == 1
