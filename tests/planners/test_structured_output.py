"""Structured output: the contract's JSON schema (live variants, eight classes) as response_format,
chosen by what litellm reports for the model, asserted on what reaches the fake server."""

from __future__ import annotations

from fake_answers import ok

from emopose import CLASSES
from emopose.contract import plan_schema
from emopose.planners.base import PlanRequest
from emopose.stages.parse import parse_output

LINE = PlanRequest("Welcome! The screen is over there.")


def _sent(fake_openai) -> dict | None:
    return fake_openai.requests[-1].get("response_format")


def _record_schema(response_format: dict) -> dict:
    return response_format["json_schema"]["schema"]["$defs"]["GestureRecord"]


def test_the_schema_comes_from_the_contract():
    schema = plan_schema(["wave", "nod"], max_gestures=3)
    record = schema["$defs"]["GestureRecord"]
    assert record["properties"]["class"]["enum"] == list(CLASSES)
    assert record["properties"]["variant"]["enum"] == ["wave", "nod"]
    assert set(record["required"]) == {"class", "variant", "intensity", "trigger", "confidence"}
    assert record["additionalProperties"] is False and schema["additionalProperties"] is False
    assert schema["properties"]["gestures"]["maxItems"] == 3 and schema["required"] == ["reply", "gestures"]


def test_json_schema_carries_the_live_variants(fake_openai, make_llm_planner, writable_library):
    planner = make_llm_planner(structured_output="json_schema", max_gestures=3)
    plan = parse_output(planner.plan(LINE), LINE.utterance)
    sent = _sent(fake_openai)
    assert sent["type"] == "json_schema" and sent["json_schema"]["strict"] is True
    variants = _record_schema(sent)["properties"]["variant"]["enum"]
    assert "pointing_b" in variants and "neutral_rest" not in variants and "comforting_hug" not in variants
    assert plan.source == "model"

    rest = writable_library.neutral_entry.q[0].tolist()
    writable_library.save({"name": "comforting_hug", "class": "comforting", "description": "a warm self hug",
                           "keyframes": [rest, [v + 0.1 for v in rest], rest]})
    planner.plan(PlanRequest("It will be all right."))
    assert "comforting_hug" in _record_schema(_sent(fake_openai))["properties"]["variant"]["enum"]


def test_unprobed_auto_asks_litellm_for_a_hosted_model_and_sends_json_schema_to_a_server(fake_openai,
                                                                                        make_llm_planner):
    make_llm_planner(model="openai/fake-model").plan(LINE)  # a server at api_base, no check() ran
    assert _sent(fake_openai)["type"] == "json_schema"
    assert make_llm_planner(model="openai/gpt-4o-mini", api_base=None).structured_output == "json_schema"
    assert make_llm_planner(model="openai/fake-model", api_base=None).structured_output == "json_object"
    make_llm_planner(structured_output="none").plan(LINE)  # prompt only
    assert _sent(fake_openai) is None


def test_json_object_schema_is_llama_cpp_pythons_form(fake_openai, make_llm_planner):
    planner = make_llm_planner(structured_output="json_object_schema")
    planner.plan(LINE)
    assert _sent(fake_openai) == {"type": "json_object", "schema": planner.answer_schema()}


def test_the_format_is_part_of_the_cache_key(fake_openai, make_llm_planner):
    make_llm_planner(structured_output="none", temperature=0).plan(LINE)
    again = make_llm_planner(structured_output="json_object", temperature=0).plan(LINE)
    assert fake_openai.count == 2 and not again.meta["cached"]


def test_the_probe_asks_in_the_same_format(fake_openai, make_llm_planner):
    fake_openai.default = ok()
    make_llm_planner(structured_output="json_schema").check()
    assert fake_openai.requests[0]["response_format"]["type"] == "json_schema"
