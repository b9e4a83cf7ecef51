import json

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from emopose.contract import Plan
from emopose.stages.parse import parse_plan


def test_bare_and_fenced_json():
    body = {"reply": "Hi!", "gestures": [{"class": "welcoming", "variant": "face_wave", "intensity": 4,
                                          "trigger": "Hi", "confidence": 0.9}]}
    for raw in (json.dumps(body), f"Sure:\n```json\n{json.dumps(body)}\n```",
                f"```\n{json.dumps(body)}\n```"):
        plan = parse_plan(raw)
        assert plan.source == "model" and plan.reply == "Hi!"
        assert plan.records[0].variant == "face_wave" and plan.records[0].intensity == 4


@pytest.mark.parametrize("intensity,expected",
                         [(9, 5), (-3, 1), (2.6, 3), ("4", 4), (1e300, 5), (float("inf"), 5)])
def test_intensity_clamped_to_integers(intensity, expected):
    raw = json.dumps({"gestures": [{"class": "agreeing", "intensity": intensity}]})
    assert parse_plan(raw).records[0].intensity == expected


def test_confidence_clamped_unknown_class_neutral():
    plan = parse_plan(json.dumps({"gestures": [{"class": "Dancing", "confidence": 7}]}))
    assert plan.records[0].cls == "neutral" and plan.records[0].confidence == 1.0
    assert "unknown class" in plan.notes[0]


def test_plain_text_is_one_neutral_record():
    plan = parse_plan("I think you should look left.")
    assert plan.source == "plain_text" and [r.cls for r in plan.records] == ["neutral"]


def test_decode_or_value_failure_falls_back_to_keywords(caplog):
    plan = parse_plan('{"reply": "No way", "gestures": [{"class": "rejecting", ', "No, please stop.")
    assert plan.source == "keyword_fallback" and plan.records[0].cls == "rejecting"
    assert "keyword fallback" in caplog.text
    plan = parse_plan('{"gestures": [{"class": "agreeing", "intensity": "very"}]}', "Yes, exactly.")
    assert plan.source == "keyword_fallback" and plan.records[0].cls == "agreeing"


def test_single_record_and_bare_list():
    assert parse_plan('{"class": "pointing", "trigger": "there"}').records[0].cls == "pointing"
    assert [r.cls for r in parse_plan('[{"class": "doubting"}, {"class": "agreeing"}]').records] == [
        "doubting", "agreeing"]


def test_deeply_nested_json_does_not_raise():
    assert isinstance(parse_plan("[" * 100_000 + "]" * 100_000), Plan)


json_values = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=True) | st.text(max_size=30),
    lambda children: st.lists(children, max_size=4) | st.dictionaries(
        st.sampled_from(["class", "variant", "intensity", "trigger", "confidence", "reply", "gestures", "x"]),
        children, max_size=6),
    max_leaves=25)


@settings(max_examples=400, deadline=None)
@given(st.one_of(st.text(max_size=300), json_values.map(lambda v: json.dumps(v)),
                 json_values.map(lambda v: "```json\n" + json.dumps(v)[:50] + "\n```")), st.text(max_size=40))
def test_fuzz_never_raises_always_valid(raw, utterance):
    plan = parse_plan(raw, utterance)
    assert isinstance(plan, Plan) and plan.records
    for record in plan.records:
        assert 1 <= record.intensity <= 5 and 0.0 <= record.confidence <= 1.0
