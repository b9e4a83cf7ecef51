"""The local-model route (issue 34): the check finds which server answers and the structured-output
form it takes, falls back past a refused form with a note, counts the prompt with the server's usage,
and a benchmark names model and server in results.json and moves its progress line per answer.
The server is tests/planners/fake_llama_cpp.py, a stub that answers as llama-cpp-python's does."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import tqdm
from fake_answers import http_error, ok
from fake_llama_cpp import MODEL_PATH, REFUSAL, fake_llama_cpp
from fake_openai import FakeOpenAI

from emopose.app import run
from emopose.jobs.suite_planning import plan_suite
from emopose.llm.errors import LLMConfigError
from emopose.planners.base import PlanRequest
from tests.conftest import synthetic_library

LINE = PlanRequest("Welcome! The screen is over there.")
BENCH = Path(__file__).parents[1] / "bench" / "fixtures" / "bench_small.jsonl"


def _formats(server: FakeOpenAI) -> list[dict | None]:
    return [body.get("response_format") for body in server.requests]


def test_auto_finds_llama_cpp_python_and_sends_the_schema_inside_json_object(make_llm_planner):
    with fake_llama_cpp() as server:
        planner = make_llm_planner(api_base=server.url, cache=False)
        planner.check()
        assert planner.plan(LINE).raw == ok().content
        sent = _formats(server)
    assert len(sent) == 2 and all(f["type"] == "json_object" for f in sent)  # the probe, then the item
    assert sent[1]["schema"] == planner.answer_schema()  # the grammar: classes and live variants
    stats = planner.stats()
    assert stats["server"] == "llama-cpp-python" and stats["served_models"] == [MODEL_PATH]
    assert stats["structured_output"] == "json_object_schema" and stats["format_notes"] == []


def test_a_refused_form_falls_back_to_the_next_with_a_note(make_llm_planner, caplog):
    with fake_llama_cpp() as server:
        server.listing = None  # an unknown server: auto starts from json_schema
        planner = make_llm_planner(api_base=server.url)
        planner.check()
        sent = _formats(server)
    assert [f["type"] for f in sent] == ["json_schema", "json_object"]  # refused once, not retried
    assert planner.structured_output == "json_object_schema"
    notes = planner.stats()["format_notes"]
    assert len(notes) == 1 and "refused structured output json_schema" in notes[0]
    assert "using json_object_schema" in notes[0] and REFUSAL[:40] in notes[0]
    assert any("refused structured output json_schema" in r.message for r in caplog.records)


def test_a_form_set_by_name_is_refused_down_to_an_error_naming_the_setting(make_llm_planner):
    with fake_llama_cpp() as server:
        server.gate = lambda body: http_error(500, REFUSAL) if body.get("response_format") else None
        with pytest.raises(LLMConfigError, match=r"refused every structured output tried \(json_schema, "
                                                 r"json_object_schema, json_object\): set "
                                                 r"planner.structured_output=auto .* or "
                                                 r"planner.structured_output=none"):
            make_llm_planner(api_base=server.url, structured_output="json_schema").check()
        auto = make_llm_planner(api_base=server.url)
        auto.check()  # auto goes down to the prompt alone, and says so
    assert auto.structured_output == "none" and len(auto.stats()["format_notes"]) == 2


def test_the_prompt_is_counted_by_the_servers_usage(make_llm_planner):
    with fake_llama_cpp() as server:
        planner = make_llm_planner(api_base=server.url, cache=False)
        planner.check()
        planner.plan_many([LINE, PlanRequest("No, thank you.")])
    stats = planner.stats()
    assert stats["probe_prompt_tokens"] > 100  # the real system prompt, as the stub counts it
    assert stats["prompt_tokens"]["counted_by"] == "server usage"
    assert stats["prompt_tokens"]["min"] >= stats["probe_prompt_tokens"] - 5


def test_progress_moves_per_answer(fake_openai, make_llm_planner, monkeypatch):
    updates = []

    class Recorded(tqdm.tqdm):
        def update(self, n=1):
            updates.append(n)
            return super().update(n)

    monkeypatch.setattr(tqdm, "tqdm", Recorded)
    planner = make_llm_planner(concurrency=1, cache=False)
    plan_suite(planner, [PlanRequest(f"Item {k}.") for k in range(5)], chunk_size=64, progress=True)
    assert updates[:5] == [1, 1, 1, 1, 1] and sum(updates) == 5  # not one jump of 5 at the end


def test_a_local_bench_run_names_model_and_server(compose, tmp_path, demonstrations_file):
    with fake_llama_cpp() as server:
        cfg = compose("+experiment=bench_all", "planner=llm_local", f"bench.path={BENCH}",
                      "job.progress=false", "job.confusion=false", "run.record=false",
                      "job.max_fallback_share=1.0", "planner.client.model=openai/local",
                      f"planner.client.api_base={server.url}", "planner.client.cache=false",
                      f"planner.demonstrations={demonstrations_file}",
                      *synthetic_library(tmp_path / "library"))
        run(cfg, tmp_path / "run")
        refused = server.served.get("http_500", 0)
    stats = json.loads((tmp_path / "run" / "results.json").read_text())["planner_stats"]
    assert stats["model"] == "openai/local" and stats["server"] == "llama-cpp-python"
    assert stats["served_models"] == [MODEL_PATH] and stats["structured_output"] == "json_object_schema"
    assert refused == 0 and stats["failed_calls"] == 0 and stats["prompt_tokens"]["max"] > 0
