"""Fail fast and say why: check() before any item and the mid-run abort, against real local servers
(tests/planners/fake_openai.py: a wrong key gets 401, an unknown model 404, a long prompt the 400)."""

from __future__ import annotations

import pytest
from fake_answers import http_error, ok
from fake_openai import FakeOpenAI

from emopose.build import ConfigError, check_planner
from emopose.jobs.suite_planning import plan_suite
from emopose.llm.errors import LLMConfigError
from emopose.planners.base import PlannerFailure, PlanRequest

LINE = PlanRequest("Welcome! The screen is over there.")


def dead_url() -> str:
    """The address of a server that has stopped: connections to it are refused."""
    with FakeOpenAI() as server:
        return server.url


def test_a_dead_endpoint_is_named(make_llm_planner):
    url = dead_url()
    with pytest.raises(LLMConfigError, match=f"nothing answers at {url}.*planner.client.api_base"):
        make_llm_planner(api_base=url).check()


def test_a_rejected_key_is_named(make_llm_planner):
    with FakeOpenAI(api_key="right") as server:
        with pytest.raises(LLMConfigError, match=r"rejected the API key \(HTTP 401\)"):
            make_llm_planner(api_base=server.url, api_key="wrong").check()
        make_llm_planner(api_base=server.url, api_key="right").check()
        assert server.count == 2  # one probe each, no retries of a 401


def test_an_unknown_model_is_named(make_llm_planner):
    with FakeOpenAI(models=("fake-model",)) as server:
        with pytest.raises(LLMConfigError, match=r"does not know model 'openai/other' .*HTTP 404"):
            make_llm_planner(api_base=server.url, model="openai/other").check()
        make_llm_planner(api_base=server.url).check()


def test_a_server_side_context_overflow_is_named(make_llm_planner):
    with (FakeOpenAI(context_window=1000) as server,  # the full prompt is about 2,000 tokens here
          pytest.raises(LLMConfigError, match="does not fit .*context window.*prompt=compact")):
        make_llm_planner(api_base=server.url).check()


def test_a_configured_window_is_checked_without_a_request(fake_openai, make_llm_planner):
    with pytest.raises(LLMConfigError, match=r"prompt \(\d+ tokens\) plus planner.client.max_tokens \(1024\) "
                                             r"exceeds openai/fake-model's context window of 2048 tokens"):
        make_llm_planner(context_window=2048).check()
    assert fake_openai.count == 0
    make_llm_planner(context_window=8192).check()


def test_the_probe_is_one_real_request_and_no_item(fake_openai, make_llm_planner, tmp_path):
    planner = make_llm_planner()
    planner.check()
    body = fake_openai.requests[0]
    assert fake_openai.count == 1 and body["max_tokens"] == 1
    assert body["messages"][0]["content"] == planner.system_prompt()  # a real prompt: overflow shows here
    assert planner.stats()["calls"] == 0 and not (tmp_path / "llm-cache").exists()  # not counted, not cached
    make_llm_planner(api_base=dead_url(), probe=False).check()  # replaying from the cache: no probe


def test_build_turns_a_failed_check_into_a_config_error(make_llm_planner):
    with pytest.raises(ConfigError, match="planner: nothing answers at http://127.0.0.1"):
        check_planner(make_llm_planner(api_base=dead_url()))


def test_a_server_dying_mid_run_stops_the_run(make_llm_planner):
    with FakeOpenAI() as server:
        planner = make_llm_planner(api_base=server.url, cache=False, abort_after=3)
        assert not planner.plan(LINE).fallback
    for _ in range(2):  # the first failures still answer (keyword rules, flagged) ...
        assert planner.plan(LINE).fallback
    with pytest.raises(PlannerFailure, match="stopped after 3 failed calls in a row: nothing answers"):
        planner.plan(LINE)  # ... the third stops the run


def test_a_suite_run_against_a_dead_endpoint_stops_instead_of_scoring(make_llm_planner):
    planner = make_llm_planner(api_base=dead_url(), concurrency=4)
    with pytest.raises(PlannerFailure, match="nothing answers"):
        plan_suite(planner, [PlanRequest(f"item {k}") for k in range(20)], progress=False)


def test_transient_failures_never_abort(fake_openai, make_llm_planner):
    fake_openai.default = http_error(500)
    planner = make_llm_planner(cache=False, max_retries=0, abort_after=2)
    assert all(planner.plan(LINE).fallback for _ in range(4))  # retried and counted, but not unmendable


def test_a_good_answer_resets_the_abort_count(fake_openai, make_llm_planner):
    fake_openai.script(http_error(401), ok(), http_error(401), ok(), http_error(401))
    planner = make_llm_planner(cache=False, abort_after=2)
    assert [planner.plan(LINE).fallback for _ in range(5)] == [True, False, True, False, True]
