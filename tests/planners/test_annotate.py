"""planner=annotate: a chat model's plain-text reply, annotated by a robot-side planner (keyword here:
planner=local trains for minutes on first use; tests/planners/test_local.py covers it)."""

from __future__ import annotations

import functools

import pytest
from fake_answers import http_error, ok

from emopose.planners.base import PlanRequest
from emopose.planners.baselines.keyword import KeywordPlanner
from emopose.planners.chat.annotate import AnnotatePlanner, built_annotator
from emopose.stages.parse import parse_output

GREETING = ({"role": "user", "content": "Hi!"}, {"role": "assistant", "content": "Welcome!"})
QUESTION = PlanRequest("Where can I charge my phone?", history=GREETING)
SPOKEN = "Sure!  The charging dock is over there,\nby the window. No, don't use the lab sockets."


@pytest.fixture
def make_annotate(make_chat):
    def make(**overrides):
        settings = {"annotator": KeywordPlanner(), **overrides}
        return make_chat(AnnotatePlanner, "prompts/annotate.md", **settings)

    return make


def test_the_reply_is_the_models_words_and_every_trigger_is_in_it(fake_openai, make_annotate):
    fake_openai.default = ok(SPOKEN)
    plan = parse_output(make_annotate().plan(QUESTION), QUESTION.utterance)
    reply = " ".join(SPOKEN.split())
    assert plan.source == "model" and plan.reply == reply
    annotated = parse_output(KeywordPlanner().plan(PlanRequest(reply))).records
    assert plan.records == annotated  # the annotator's plan
    assert {"pointing", "rejecting"} <= {r.cls for r in plan.records}
    assert all(r.trigger and r.trigger in reply for r in plan.records)  # say-do holds by construction
    body = fake_openai.requests[0]
    assert "response_format" not in body and "Person: " in body["messages"][0]["content"]
    assert [m["role"] for m in body["messages"]] == ["system", "user", "assistant", "user"]


def test_the_annotator_hears_what_the_reply_answers(fake_openai, writable_library, make_annotate):
    heard = []

    class Listening(KeywordPlanner):
        def plan(self, request):
            heard.append(request)
            return super().plan(request)

    fake_openai.default = ok(SPOKEN)
    make_annotate(annotator=functools.partial(Listening)).plan(QUESTION)  # a factory, as Hydra's _partial_
    assert heard[0].history[-1] == {"role": "user", "content": QUESTION.utterance}


def test_narration_asks_no_model(fake_openai, make_annotate):
    line = PlanRequest("No, please do not touch that.")
    planner = make_annotate(mode="narrate")
    planner.check()
    outputs = planner.plan_many([line, line])
    assert fake_openai.count == 0 and outputs[0].raw == KeywordPlanner().plan(line).raw


@pytest.mark.parametrize("answer,source", [(ok("   "), "empty"), (http_error(401), "call_failed")])
def test_no_reply_is_a_counted_fallback(fake_openai, make_annotate, answer, source):
    fake_openai.default = answer
    plan = parse_output(make_annotate(max_retries=0).plan(QUESTION), QUESTION.utterance)
    assert plan.source == source and plan.fallback


def test_a_factory_is_given_the_library_only_when_its_planner_asks(writable_library):
    given = []

    def annotator(library):
        given.append(library)
        return KeywordPlanner()

    assert isinstance(built_annotator(annotator, writable_library), KeywordPlanner)
    assert given == [writable_library]
    assert isinstance(built_annotator(functools.partial(KeywordPlanner, max_records=2), writable_library),
                      KeywordPlanner)  # it takes no library: none is forced on it


def test_the_preset_composes_with_the_local_annotator_and_the_hosted_client(compose):
    planner = compose("planner=annotate").planner
    assert planner.annotator._target_ == "emopose.planners.local.planner.LocalPlanner.from_config"
    assert planner.annotator._partial_
    assert planner.mode == "respond" and planner.template.endswith("prompts/annotate.md")
    assert planner.client._target_ == "emopose.llm.client.LLMClient"
    assert planner.client.max_tokens == 256  # a few spoken sentences; the rest as conf/llm/hosted.yaml
