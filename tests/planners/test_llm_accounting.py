"""Honest accounting: every answer's source, from the fake server's answer to results.json.

Only "model" and "retried" are the model's own usable records; every other source is a fallback the
jobs count, and a suite run over its fallback limit is written, marked and then fails."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from fake_answers import (
    UNUSABLE,
    empty,
    faulty,
    fenced,
    http_error,
    loud,
    malformed,
    ok,
    plain,
    truncated,
    unknown_class,
)
from fake_openai import FakeOpenAI

from emopose.app import run
from emopose.planners.base import PlannerFailure, PlanRequest
from emopose.stages.parse import Parse, parse_output
from emopose.turn.model import Turn
from tests.conftest import synthetic_library

WELCOME = PlanRequest("Welcome! The screen is over there.")
BENCH = Path(__file__).parents[1] / "bench" / "fixtures" / "bench_small.jsonl"


@pytest.mark.parametrize("answer,source", [
    (ok(), "model"), (fenced(), "model"), (loud(), "model"), (plain(), "plain_text"), (empty(), "empty"),
    (unknown_class(), "unknown_class"), (malformed(), "keyword_fallback"), (truncated(), "keyword_fallback"),
    (ok('{"reply": "Welcome!", "gestures": []}'), "no_records")])
def test_every_answer_is_labelled_with_its_source(fake_openai, make_llm_planner, answer, source):
    fake_openai.default = answer
    plan = parse_output(make_llm_planner().plan(WELCOME), WELCOME.utterance)
    assert plan.source == source and plan.fallback == (source != "model")


def test_a_retried_answer_is_usable_and_marked(fake_openai, make_llm_planner):
    fake_openai.script(http_error(500))
    plan = parse_output(make_llm_planner().plan(WELCOME), WELCOME.utterance)
    assert plan.source == "retried" and not plan.fallback


def test_the_parse_stage_never_calls_a_failed_call_the_model(fake_openai, make_llm_planner):
    fake_openai.default = http_error(500)
    turn = Turn(WELCOME, planner_output=make_llm_planner(max_retries=0).plan(WELCOME))
    plan = Parse()(turn)
    assert plan.source == "call_failed" and plan.fallback
    assert plan.records[0].cls == "welcoming"  # the keyword rules'
    assert "InternalServerError" in plan.notes[-1]


@pytest.mark.parametrize("mode,spoken", [("narrate", WELCOME.utterance), ("respond", plain().content)])
def test_chatter_never_replaces_the_line_in_narration(fake_openai, make_llm_planner, mode, spoken):
    fake_openai.default = plain()
    plan = Parse()(Turn(WELCOME, planner_output=make_llm_planner(mode=mode).plan(WELCOME)))
    assert plan.source == "plain_text" and plan.reply == spoken


def _label_of(items: dict[str, str]):
    """The fake model's right answer for a bench item: one record of the item's label."""

    def good(body: dict) -> str:
        line = body["messages"][-1]["content"]
        cls = items.get(line, "neutral")
        return json.dumps({"reply": line, "gestures": [{"class": cls, "variant": f"{cls}_a", "intensity": 3,
                                                        "trigger": line, "confidence": 0.9}]})

    return good


@pytest.mark.parametrize("limit,fails", [(1.0, False), (0.1, True)])
def test_a_faulty_server_is_counted_answer_by_answer(compose, tmp_path, demonstrations_file, limit, fails):
    items = {r["text"]: r["label"] for r in map(json.loads, BENCH.read_text().splitlines())}
    mix = ("malformed", "truncated", "plain", "unknown_class", "fenced", "loud", "http_500")
    with FakeOpenAI(faulty(0.0, 0.3, seed=3, mix=mix, good=_label_of(items))) as server:
        cfg = compose("+experiment=bench_all", "planner=llm", f"bench.path={BENCH}", "job.progress=false",
                      "job.confusion=false", "run.record=false", f"job.max_fallback_share={limit}",
                      "planner.client.model=openai/fake-model", f"planner.client.api_base={server.url}",
                      "planner.client.temperature=0", "planner.client.cache=false",
                      "planner.client.backoff_s=0.001",
                      "planner.client.concurrency=1",  # one order: seeded draws
                      f"planner.demonstrations={demonstrations_file}",
                      *synthetic_library(tmp_path / "library"))
        if fails:
            with pytest.raises(PlannerFailure,
                               match=r"fell back on \d+ answers .*> job.max_fallback_share 10 %"):
                run(cfg, tmp_path / "run")
        else:
            run(cfg, tmp_path / "run")
        served = server.served
    results = json.loads((tmp_path / "run" / "results.json").read_text())
    unusable = sum(served[kind] for kind in UNUSABLE)
    assert unusable > 0 and results["fallbacks"] == unusable  # every unusable answer counted, no more
    sources = [p["source"] for p in results["predictions"]]
    assert results["sources"] == {s: sources.count(s) for s in set(sources)}
    assert sources.count("retried") <= served["http_500"]  # a retry may draw another fault, or another 500
    harmful = sum(p["source"] not in ("model", "retried") and p["pred"] != p["label"]
                  for p in results["predictions"])
    assert results["accuracy"]["overall"]["mean"] == pytest.approx(100 * (1 - harmful / results["n"]))
    assert ("FALLBACKS" in (tmp_path / "run" / "results.md").read_text()) == fails


def test_the_plan_job_reports_the_true_source(compose, tmp_path, demonstrations_file, capsys):
    with FakeOpenAI() as server:
        server.script(ok(), http_error(500))  # the probe passes, the turn's call fails
        cfg = compose("+experiment=plan", "planner=llm", "utterance=Welcome aboard", "run.record=false",
                      "planner.client.model=openai/fake-model", f"planner.client.api_base={server.url}",
                      "planner.client.max_retries=0", "planner.client.cache=false",
                      f"planner.demonstrations={demonstrations_file}",
                      *synthetic_library(tmp_path / "library"))
        results = run(cfg, tmp_path / "run")
    assert results["plan_source"] == "call_failed" and "plan from call_failed" in capsys.readouterr().out
    assert results["turn"]["plan"]["source"] == "call_failed"  # what the web UI shows
