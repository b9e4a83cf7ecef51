"""LLM planner throughput and robustness against a local fake provider (no network, no API key).

480 requests (one EmoPose-Bench run) go through LLMPlanner.plan_many -> litellm -> real HTTP on
127.0.0.1 to tests/planners/fake_openai.py, which answers every request after --delay seconds;
--bad-rate of the answers are bad, drawn evenly from --mix (default: half malformed JSON, half HTTP
500; each retry draws again). Reports wall time (target <= 15 s for 480 requests at 200 ms), crashes
(plan_many raising or an output missing: target 0), retries, how the parser saw the answers, latency
(server time and queueing apart), and the accounting (issue 17): every unusable answer the server
sent must be counted as a fallback, and top-1 accuracy (the right class is the good answer's,
welcoming) must equal 1 minus the share of fallbacks that chose another class.
The response cache is off so every request reaches the server.
Run: python benchmarks/llm_bench_fake.py [--requests 480] [--concurrency 16] [--bad-rate 0.3 --mix malformed
truncated plain unknown_class fenced loud http_500]  -> JSON on stdout.
"""

from __future__ import annotations

import argparse
import json
import logging
import subprocess
import sys
import tempfile
import time
import urllib.request
from collections import Counter
from contextlib import contextmanager
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "tests")]

from conftest import load_library, make_library_dir
from planners.fake_answers import FAULTS, PLAN, UNUSABLE

from emopose.llm.client import LLMClient
from emopose.planners.base import PlanRequest, plan_all
from emopose.planners.chat.llm import LLMPlanner
from emopose.stages.parse import parse_output

FAKE_SERVER = ROOT / "tests" / "planners" / "fake_openai.py"
RIGHT_CLASS = PLAN["gestures"][0]["class"]


@contextmanager
def fake_server(delay_s: float, bad_rate: float, seed: int, mix: list[str]):
    """The fake provider in its own process, as a real provider would be: (url, stats())."""
    proc = subprocess.Popen([sys.executable, str(FAKE_SERVER), "--delay", str(delay_s), "--bad-rate",
                             str(bad_rate), "--seed", str(seed), "--mix", *mix], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True)
    try:
        url = json.loads(proc.stdout.readline())["url"]
        stats_url = url.removesuffix("/v1") + "/stats"

        def stats() -> dict:
            with urllib.request.urlopen(stats_url, timeout=5) as response:
                return json.load(response)

        yield url, stats
    finally:
        proc.stdin.close()  # the server exits when its stdin closes
        try:
            proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            proc.kill()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--requests", type=int, default=480)
    parser.add_argument("--delay", type=float, default=0.2, help="server answer time, s")
    parser.add_argument("--bad-rate", type=float, default=0.2)
    parser.add_argument("--concurrency", type=int, default=16)
    parser.add_argument("--max-retries", type=int, default=3)
    parser.add_argument("--backoff", type=float, default=1.0, help="first backoff, s (planner default 1.0)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--model", default="openai/gpt-4o-mini",
                        help="any litellm model string; served by the fake")
    parser.add_argument("--target-s", type=float, default=15.0)
    parser.add_argument("--mix", nargs="+", default=["malformed", "http_500"], choices=sorted(FAULTS))
    args = parser.parse_args()

    logging.getLogger("emopose.stages.parse").setLevel(logging.ERROR)  # 10% malformed: expected warnings
    with tempfile.TemporaryDirectory() as tmp, fake_server(args.delay, args.bad_rate, args.seed,
                                                           args.mix) as (url, stats):
        library = load_library(make_library_dir(Path(tmp) / "library"))
        planner = LLMPlanner(library=library, template=str(ROOT / "prompts/structured.md"),
                             demonstrations=str(ROOT / "prompts/demonstrations.jsonl"),
                             client=LLMClient(model=args.model, api_base=url, cache=False,
                                              concurrency=args.concurrency, max_retries=args.max_retries,
                                              backoff_s=args.backoff, timeout_s=10.0))
        requests = [PlanRequest(f"Item {k}: the charging dock is over there by the window.")
                    for k in range(args.requests)]
        planner.plan(requests[0])  # warm-up outside the timing: litellm's lazy imports take seconds
        planner.reset_stats()
        before = stats()
        started = time.perf_counter()
        try:
            outputs, crash = plan_all(planner, requests), None
        except Exception as exc:  # noqa: BLE001 - the benchmark's point is that this never happens
            outputs, crash = [], f"{type(exc).__name__}: {exc}"
        wall_s = time.perf_counter() - started
        after, counters = stats(), planner.stats()
    served = Counter(after["served"])
    served.subtract(before["served"])
    plans = [parse_output(o, r.utterance) for o, r in zip(outputs, requests)]
    unusable = sum(served[kind] for kind in UNUSABLE)
    fallbacks = sum(p.fallback for p in plans)
    harmful = sum(p.fallback and p.top_class != RIGHT_CLASS for p in plans)
    accuracy = sum(p.top_class == RIGHT_CLASS for p in plans) / max(1, len(plans))
    report = {
        "requests": args.requests, "model": args.model, "concurrency": args.concurrency,
        "answer_delay_s": args.delay, "bad_rate": args.bad_rate,
        "wall_s": round(wall_s, 3), "target_wall_s": args.target_s, "within_target": wall_s <= args.target_s,
        "requests_per_s": round(args.requests / wall_s, 1),
        "crashes": int(crash is not None), "crash": crash, "missing_outputs": args.requests - len(outputs),
        "server_requests": after["requests"] - before["requests"], "served": dict(+served),
        "retries": counters["retries"], "failed_calls": counters["failed_calls"],
        "sources": dict(Counter(p.source for p in plans)),
        "unusable_answers_sent": unusable, "fallbacks_counted": fallbacks,
        "every_unusable_answer_counted": fallbacks == unusable + counters["failed_calls"],
        "accuracy": round(accuracy, 4), "harmful_share": round(harmful / max(1, len(plans)), 4),
        "accuracy_is_1_minus_harmful_share": abs(accuracy - (1 - harmful / max(1, len(plans)))) < 1e-9,
        "latency_mean_s": round(counters["latency_mean_s"], 3),
        "latency_p95_s": round(counters["latency_p95_s"], 3),
        "queue_mean_s": round(counters["queue_mean_s"], 3),
        "queue_p95_s": round(counters["queue_p95_s"], 3),
    }
    print(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
