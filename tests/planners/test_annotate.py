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


def test_the_prompt_states_the_bound_and_a_long_reply_ends_at_a_sentence_boundary(fake_openai, make_annotate):
    long_reply = " ".join(f"Sentence {k} is about the lab and what we do in it every day." for k in range(18))
    fake_openai.default = ok(long_reply + "\x07")
    planner = make_annotate(max_sentences=2, max_speech_s=30)
    plan = parse_output(planner.plan(QUESTION), QUESTION.utterance)
    assert plan.reply == "Sentence 0 is about the lab and what we do in it every day. " \
                         "Sentence 1 is about the lab and what we do in it every day."
    system = fake_openai.requests[0]["messages"][0]["content"]
    assert "at most 2 short sentences, no more than 30 seconds of speech" in system


def test_the_speech_bound_and_the_reply_length_cut_at_sentence_boundaries(fake_openai, make_annotate):
    sentence = "This sentence has exactly ten words in it, you see."  # about 3.6 s at 165 words a minute
    fake_openai.default = ok(" ".join([sentence] * 8))
    by_speech = parse_output(make_annotate(max_sentences=8, max_speech_s=8).plan(QUESTION)).reply
    assert by_speech == " ".join([sentence] * 2)
    by_length = parse_output(make_annotate(max_sentences=8, max_speech_s=60).plan(QUESTION)).reply
    assert by_length == " ".join([sentence] * 3)  # four would pass the contract's 200 characters


@pytest.mark.parametrize("setting", [{"max_sentences": 0}, {"max_speech_s": 0}])
def test_a_bound_below_one_sentence_is_refused(make_annotate, setting):
    with pytest.raises(ValueError, match=f"planner.{next(iter(setting))} = 0 must be"):
        make_annotate(**setting)
