"""LLM planner wall time in two small cases against the scripted local server (no network, no key).

  waves     --requests utterances (16) through plan_many with --concurrency 8, every answer after
            0.2 s: ideally two waves, 0.4 s (target < 1.5 s; sixteen sequential calls take 3.2 s)
  timeout   one plan() whose answers take 3 s, with timeout_s 0.3 and one retry: both attempts
            are abandoned, then the keyword fallback answers: ideally 0.6 s (target < 2.5 s)
Each case runs --repeats times (litellm's lazy imports are warmed up first, outside the timing);
reports median and max wall seconds and whether the max meets the target. tests/planners/test_llm.py
checks the same behaviour with the server's counters (requests in progress at once, answers sent).
Run: python benchmarks/llm_latency.py [--repeats 5]  -> JSON on stdout.
"""

from __future__ import annotations

import argparse
import json
import logging
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "tests"), str(ROOT / "tests" / "planners")]

from conftest import load_library, make_library_dir
from fake_openai import Answer, FakeOpenAI, slow

from emopose.llm.client import LLMClient
from emopose.planners.base import PlanRequest, plan_all
from emopose.planners.chat.llm import LLMPlanner


def echo(body: dict, index: int) -> Answer:
    return Answer(content=json.dumps({"reply": body["messages"][-1]["content"], "gestures": []}), delay_s=0.2)


def timed(run, repeats: int, target_s: float) -> dict:
    walls = []
    for _ in range(repeats):
        started = time.perf_counter()
        run()
        walls.append(time.perf_counter() - started)
    return {"median_s": round(statistics.median(walls), 3), "max_s": round(max(walls), 3),
            "target_s": target_s, "within_target": max(walls) < target_s}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--requests", type=int, default=16)
    parser.add_argument("--concurrency", type=int, default=8)
    args = parser.parse_args()
    logging.getLogger("emopose").setLevel(logging.ERROR)  # the timeout case logs its fallback on purpose
    with tempfile.TemporaryDirectory() as tmp, FakeOpenAI() as server:
        library = load_library(make_library_dir(Path(tmp) / "library"))

        def planner(**settings) -> LLMPlanner:
            return LLMPlanner(library=library, template=str(ROOT / "prompts/structured.md"),
                              demonstrations=str(ROOT / "prompts/demonstrations.jsonl"),
                              client=LLMClient(model="openai/fake-model", api_base=server.url, cache=False,
                                               backoff_s=0.001, backoff_max_s=0.01, **settings))

        planner().plan(PlanRequest("Warm-up: hello there."))
        waves = planner(concurrency=args.concurrency, timeout_s=10.0)
        requests = [PlanRequest(f"utterance {k}") for k in range(args.requests)]
        server.default = echo
        report = {"waves": {"requests": args.requests, "concurrency": args.concurrency,
                            **timed(lambda: plan_all(waves, requests), args.repeats, 1.5)}}
        server.default = slow(3.0)
        patient = planner(timeout_s=0.3, max_retries=1)
        report["timeout"] = timed(lambda: patient.plan(PlanRequest("Hello there, welcome aboard!")),
                                  args.repeats, 2.5)
    print(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
