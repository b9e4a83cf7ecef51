"""Fail fast and say why (issue 17): a misconfigured LLM endpoint must end a benchmark run with exit 2
and the cause named, within 10 s, before any item is scored. Also: the compact prompt's size.

Runs the real CLI (python -m emopose +experiment=bench_all planner=llm ...) as a user would, against
tests/planners/fake_openai.py in its own process (it wants a key, knows one model, and refuses
prompts over a 2,048-token window, as a small llama.cpp server does). Cases: a dead endpoint, a wrong
key, an unknown model, a context overflow (the full prompt), and a control run that must pass (the
compact prompt on the 24-item fixture suite). Token counts are litellm's token_counter.
Run: python benchmarks/llm_fail_fast.py  -> JSON on stdout.
"""

from __future__ import annotations

import json
import os
import resource
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT)]

from emopose.config import CONFIG_DIR, register_resolvers  # noqa: E402

FAKE_SERVER = ROOT / "tests" / "planners" / "fake_openai.py"
FIXTURE = ROOT / "tests" / "bench" / "fixtures" / "bench_small.jsonl"
TARGET_S = 10.0
KEY, MODEL, WINDOW = "sk-right", "fake-model", 2048


def free_port() -> int:
    """A port nothing listens on (bound, then released): connections to it are refused."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _cpu_s() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def cli(run_dir: Path, *overrides: str) -> tuple[int, float, float, str]:
    """(exit code, wall s, CPU s of the process: the load-independent part on a shared machine,
    last stderr line)."""
    env = {**os.environ, "HYDRA_FULL_ERROR": "1", "LITELLM_LOCAL_MODEL_COST_MAP": "True"}
    started, cpu = time.perf_counter(), _cpu_s()
    done = subprocess.run([sys.executable, "-m", "emopose", "+experiment=bench_all", "planner=llm",
                           "planner.client.cache=false", "job.progress=false", "run.record=false",
                           f"hydra.run.dir={run_dir}", *overrides],
                          cwd=ROOT, env=env, capture_output=True, text=True, timeout=300)
    last = (done.stderr.strip().splitlines() or [""])[-1]
    return done.returncode, time.perf_counter() - started, _cpu_s() - cpu, last


def prompt_sizes() -> dict:
    from hydra import compose, initialize_config_dir
    from hydra.utils import instantiate

    from emopose.llm.check import prompt_tokens
    from emopose.planners.base import PlanRequest
    from emopose.planners.chat.planner import PROBE_LINE

    register_resolvers()
    sizes = {}
    for prompt in ("structured", "compact"):
        with initialize_config_dir(config_dir=str(CONFIG_DIR), version_base="1.3"):
            cfg = compose("config", overrides=["planner=llm", f"prompt={prompt}"])
        planner = instantiate(cfg.planner, _convert_="all", _partial_=True)(library=instantiate(cfg.library))
        messages = planner.messages(PlanRequest(PROBE_LINE))
        sizes[prompt] = {"system_chars": len(messages[0]["content"]),
                         "tokens": prompt_tokens(planner.client.model, messages)}
    return sizes


def main() -> None:
    server = subprocess.Popen([sys.executable, str(FAKE_SERVER), "--api-key", KEY, "--models", MODEL,
                               "--context-window", str(WINDOW)],
                              stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        url = json.loads(server.stdout.readline())["url"]
        good = [f"planner.client.api_base={url}", f"planner.client.api_key={KEY}",
                f"planner.client.model=openai/{MODEL}"]
        cases = {
            "dead_endpoint": ([f"planner.client.api_base=http://127.0.0.1:{free_port()}/v1", *good[1:],
                               "prompt=compact"], "nothing answers"),
            "wrong_key": ([*good, "planner.client.api_key=sk-wrong", "prompt=compact"],
                          "rejected the API key"),
            "unknown_model": ([*good, "planner.client.model=openai/no-such-model", "prompt=compact"],
                              "does not know model"),
            "context_overflow": (good, "context window"),
            "control_compact": ([*good, "prompt=compact", f"bench.path={FIXTURE}",
                                 "planner.client.temperature=0", "job.confusion=false"], None),
        }
        report = {}
        with tempfile.TemporaryDirectory() as tmp:
            for name, (overrides, cause) in cases.items():
                run_dir = Path(tmp) / name
                rc, wall, cpu, last = cli(run_dir, *overrides)
                scored = (run_dir / "results.json").exists()
                ok = (rc == 0 and scored if cause is None
                      else rc == 2 and cause in last and not scored and wall <= TARGET_S)
                report[name] = {"exit": rc, "wall_s": round(wall, 2), "cpu_s": round(cpu, 2),
                                "stderr_last_line": last[:300],
                                "results_written": scored, "meets_target": ok}
    finally:
        server.stdin.close()
        server.wait(timeout=10)
    print(json.dumps({"target_s": TARGET_S, "load_average_1min": round(os.getloadavg()[0], 2),
                      "cpu_cores": os.cpu_count(), "server_context_window": WINDOW, "cases": report,
                      "prompt_sizes": prompt_sizes(), "compact_budget_tokens": 1200}, indent=2))


if __name__ == "__main__":
    main()
