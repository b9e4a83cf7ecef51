"""planner=llm against a real local HTTP server (tests/planners/fake_openai.py); litellm is not mocked."""

from __future__ import annotations

import asyncio
import json

import pytest
from fake_answers import (
    PLAN_JSON,
    Answer,
    empty,
    http_error,
    malformed,
    ok,
    oversized,
    rate_limited,
    slow,
    truncated,
)

from emopose.llm.client import LLMConfigError
from emopose.planners.base import PlanRequest, plan_all
from emopose.stages.parse import parse_plan

WELCOME = PlanRequest("Welcome! The screen is over there.")


def test_good_answer_is_returned_raw(fake_openai, make_llm_planner):
    out = make_llm_planner().plan(WELCOME)
    assert (out.raw, out.fallback, out.error) == (PLAN_JSON, False, None)
    assert out.meta["attempts"] == 1 and out.latency_s > 0
    assert [r.cls for r in parse_plan(out.raw, WELCOME.utterance).records] == ["welcoming", "pointing"]
    body = fake_openai.requests[0]
    assert body["model"] == "fake-model" and body["temperature"] == 0.7
    assert fake_openai.paths == ["/v1/chat/completions"]


@pytest.mark.parametrize("failures", [[http_error(500)], [http_error(502), http_error(503)],
                                      [rate_limited()]])
def test_transient_errors_are_retried(fake_openai, make_llm_planner, failures):
    fake_openai.script(*failures, ok())
    planner = make_llm_planner()
    out = planner.plan(WELCOME)
    assert not out.fallback and out.raw == PLAN_JSON
    assert fake_openai.count == len(failures) + 1
    assert out.meta["attempts"] == len(failures) + 1
    assert planner.stats()["retries"] == len(failures)


def test_fallback_after_exhausting_retries(fake_openai, make_llm_planner):
    fake_openai.default = http_error(500)
    planner = make_llm_planner(max_retries=2)
    out = planner.plan(PlanRequest("Hello there, welcome aboard!"))
    assert fake_openai.count == 3
    assert out.fallback and "InternalServerError" in out.error and "3 attempt" in out.error
    assert parse_plan(out.raw).records[0].cls == "welcoming"  # keyword baseline answer
    stats = planner.stats()
    assert (stats["calls"], stats["retries"], stats["failed_calls"]) == (1, 2, 1)


@pytest.mark.parametrize("status", [400, 401, 404])
def test_client_errors_are_not_retried(fake_openai, make_llm_planner, status):
    fake_openai.default = http_error(status)
    planner = make_llm_planner()
    out = planner.plan(WELCOME)
    assert fake_openai.count == 1 and out.fallback
    assert planner.stats()["retries"] == 0


def test_timeouts_are_retried_then_fall_back(fake_openai, make_llm_planner):
    fake_openai.default = slow(3.0)
    planner = make_llm_planner(timeout_s=0.3, max_retries=1)
    out = planner.plan(WELCOME)
    assert out.fallback and "Timeout" in out.error
    # both attempts were given up before their 3 s answer came (wall time: benchmarks/llm_latency.py)
    assert fake_openai.count == 2 and fake_openai.answered == 0


def test_rerun_is_served_from_the_cache(fake_openai, make_llm_planner):
    first = make_llm_planner().plan(WELCOME)
    again = make_llm_planner()  # a new planner: the cache is on disk, not in memory
    second = again.plan(WELCOME)
    assert fake_openai.count == 1
    assert second.raw == first.raw and second.meta["cached"] and not second.fallback
    assert again.stats()["cache_hits"] == 1 and again.stats()["model_calls"] == 0


def test_cache_off_always_asks_the_model(fake_openai, make_llm_planner):
    planner = make_llm_planner(cache=False)
    planner.plan(WELCOME)
    planner.plan(WELCOME)
    assert fake_openai.count == 2 and planner.stats()["cache_hits"] == 0


def test_each_pass_is_its_own_draw_when_sampling(fake_openai, make_llm_planner):
    sampled = make_llm_planner(temperature=0.7)
    assert sampled.sampled
    for k in (0, 1):
        sampled.client.pass_index = k  # what a suite job does before pass k
        sampled.plan(WELCOME)
    assert fake_openai.count == 2

    rerun = make_llm_planner(temperature=0.7)  # a rerun (new process) replays both passes
    for k in (0, 1):
        rerun.client.pass_index = k
        assert rerun.plan(WELCOME).meta["cached"]
    assert fake_openai.count == 2

    unaware = make_llm_planner(temperature=0.7)  # a job that never sets pass_index still gets new draws
    for _ in range(3):
        unaware.plan(WELCOME)
    assert fake_openai.count == 2 + 2  # draw 0 was cached above; draws 1 and 2 are new


def test_greedy_decoding_shares_one_answer_across_passes(fake_openai, make_llm_planner):
    greedy = make_llm_planner(temperature=0.0)
    assert not greedy.sampled
    for k in range(3):
        greedy.client.pass_index = k
        greedy.plan(WELCOME)
    assert fake_openai.count == 1


@pytest.mark.parametrize("answer,source", [(malformed(), "keyword_fallback"), (empty(), "empty"),
                                           (truncated(), "keyword_fallback"), (oversized(), "model")])
def test_bad_answers_reach_the_parser_untouched(fake_openai, make_llm_planner, answer, source):
    fake_openai.default = answer
    out = make_llm_planner().plan(WELCOME)
    assert not out.fallback and out.raw == answer.content
    assert parse_plan(out.raw, WELCOME.utterance).source == source


def test_empty_answers_are_not_cached(fake_openai, make_llm_planner):
    fake_openai.script(empty())
    planner = make_llm_planner(temperature=0.0)  # greedy: an identical request has one cache key
    assert planner.plan(WELCOME).raw == ""
    assert planner.plan(WELCOME).raw == PLAN_JSON and fake_openai.count == 2


def _system(body: dict) -> str:
    return body["messages"][0]["content"]


def test_request_carries_the_live_library_guide(fake_openai, make_llm_planner, writable_library):
    planner = make_llm_planner()
    planner.plan(PlanRequest("first"))
    guide = _system(fake_openai.requests[0])
    assert "comforting_a (class default)" in guide and "pointing_b" in guide
    assert "${" not in guide and "Example 5" in guide
    assert "comforting_hug" not in guide

    rest = writable_library.neutral_entry.q[0].tolist()
    writable_library.save({"name": "comforting_hug", "class": "comforting", "description": "a warm self hug",
                           "keyframes": [rest, [v + 0.1 for v in rest], rest]})
    planner.plan(PlanRequest("second"))  # same planner object, no rebuild
    assert "comforting_hug: a warm self hug" in _system(fake_openai.requests[1])


def test_request_carries_history_and_image(fake_openai, make_llm_planner, tmp_path):
    history = ({"role": "user", "content": "Where is my bag?"},
               {"role": "assistant", "content": "Which bag?"})
    png = b"\x89PNG\r\n\x1a\n" + b"0" * 32
    make_llm_planner().plan(PlanRequest("The blue one, on the chair.", history=history, image=png))
    messages = fake_openai.requests[0]["messages"]
    assert [m["role"] for m in messages] == ["system", "user", "assistant", "user"]
    assert messages[1]["content"] == "Where is my bag?" and messages[2]["content"] == "Which bag?"
    text, image = messages[3]["content"]
    assert text == {"type": "text", "text": "The blue one, on the chair."}
    assert image["type"] == "image_url"
    assert image["image_url"]["url"].startswith("data:image/png;base64,iVBOR")

    photo = tmp_path / "frame.jpg"
    photo.write_bytes(b"\xff\xd8\xff" + b"1" * 16)
    make_llm_planner().plan(PlanRequest("What is that?", image=str(photo)))
    sent = fake_openai.requests[1]["messages"][-1]["content"][1]
    assert sent["image_url"]["url"].startswith("data:image/jpeg")


def test_unreadable_image_falls_back(fake_openai, make_llm_planner, tmp_path):
    out = make_llm_planner().plan(PlanRequest("What is that?", image=str(tmp_path / "missing.png")))
    assert out.fallback and "missing.png" in out.error and fake_openai.count == 0


def _echo(body: dict, index: int) -> Answer:
    utterance = body["messages"][-1]["content"]
    # long enough that all eight of a wave are in flight together even on a loaded machine
    return Answer(content=json.dumps({"reply": utterance, "gestures": []}), delay_s=1.0)


def test_plan_many_is_concurrent_and_ordered(fake_openai, make_llm_planner):
    fake_openai.default = _echo
    planner = make_llm_planner(concurrency=8)
    requests = [PlanRequest(f"utterance {k}") for k in range(16)]
    outputs = plan_all(planner, requests)
    # eight at a time, never more (wall time of the two waves: benchmarks/llm_latency.py)
    assert fake_openai.peak == 8 and fake_openai.answered == 16
    assert [json.loads(o.raw)["reply"] for o in outputs] == [r.utterance for r in requests]
    stats = planner.stats()
    assert stats["calls"] == 16 and stats["latency_mean_s"] >= 1.0 and stats["latency_p95_s"] >= 1.0


def test_plan_many_works_inside_a_running_event_loop(fake_openai, make_llm_planner):
    planner = make_llm_planner()

    async def handler():  # e.g. an async web endpoint calling the sync API
        return planner.plan_many([WELCOME, WELCOME])

    assert len(asyncio.run(handler())) == 2


def test_check_reports_missing_key_and_bad_model(make_llm_planner, monkeypatch):
    monkeypatch.delenv("OPENAI_API_KEY", raising=False)
    with pytest.raises(LLMConfigError, match="OPENAI_API_KEY"):
        make_llm_planner(api_base=None, model="openai/gpt-4o-mini").check()
    with pytest.raises(LLMConfigError, match="not a litellm model string"):
        make_llm_planner(model="no-such-provider/model-x", api_base=None).check()
    make_llm_planner().check()  # a local api_base needs no key
    monkeypatch.setenv("OPENAI_API_KEY", "sk-test")
    make_llm_planner(api_base=None, model="openai/gpt-4o-mini", probe=False).check()  # no network here


def test_queueing_is_counted_apart_from_server_time(fake_openai, make_llm_planner):
    fake_openai.default = slow(0.2)
    planner = make_llm_planner(concurrency=1, cache=False)
    first, _, last = plan_all(planner, [PlanRequest(f"line {k}") for k in range(3)])
    assert first.meta["queue_s"] < first.latency_s  # one slot: the first goes straight to the server ...
    assert last.meta["queue_s"] >= first.latency_s  # ... the last waited while the others held it
    assert last.latency_s < last.meta["queue_s"]  # its latency is its own call, not the two calls before it
    stats = planner.stats()
    assert stats["queue_mean_s"] > 0 and stats["latency_mean_s"] >= 0.2
