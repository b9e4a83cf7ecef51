"""Local planner latency per utterance after load (target p95 <= 20 ms with history).

    python benchmarks/local_planner.py [--items 480] [planner.OVERRIDE=VALUE ...]
The planner is built from the composed Hydra config (conf/planner/local.yaml), as the app builds it.
Two runs: the bench texts alone, and the context suite's final utterances after their dialogue history
(the history is read in the same forward pass, so it lengthens the input). Prints JSON: load time,
per-utterance latency mean/p50/p95/max in ms and records per plan, for each run.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
from hydra import compose, initialize_config_dir

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout without installing

from emopose.build import make
from emopose.config import CONFIG_DIR, PROJECT_ROOT
from emopose.planners.base import PlanRequest


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--items", type=int, default=480)
    parser.add_argument("overrides", nargs="*", help="Hydra overrides, e.g. planner.bf16_inference=false")
    args = parser.parse_args()
    with initialize_config_dir(config_dir=str(CONFIG_DIR), version_base="1.3"):
        cfg = compose("config", overrides=["planner=local", *args.overrides])
    library = make(cfg.library, "library")
    started = time.perf_counter()
    planner = make(cfg.planner, "planner", library=library)
    load_s = time.perf_counter() - started
    bench = [PlanRequest(json.loads(line)["text"]) for line in
             Path(PROJECT_ROOT / "experiments/bench/emopose_bench.jsonl").read_text().splitlines()]
    dialogues = [PlanRequest(row["text"], history=tuple(row["history"])) for row in map(json.loads, Path(
        PROJECT_ROOT / "experiments/context/context_suite.jsonl").read_text().splitlines())]
    planner.plan(PlanRequest("Warm-up: hello there, look at that."))
    print(json.dumps({"load_s": round(load_s, 2), "without_history": timings(planner, bench[: args.items]),
                      "with_history": timings(planner, dialogues[: args.items])}, indent=2))


def timings(planner, requests: list[PlanRequest]) -> dict:
    latencies, records = [], []
    for request in requests:
        output = planner.plan(request)
        latencies.append(output.latency_s * 1e3)
        records.append(len(json.loads(output.raw)["gestures"]))
    ms = np.asarray(latencies)
    return {"items": len(requests),
            "latency_ms": {"mean": round(float(ms.mean()), 2), "p50": round(float(np.median(ms)), 2),
                           "p95": round(float(np.percentile(ms, 95)), 2), "max": round(float(ms.max()), 2)},
            "records_per_plan_mean": round(float(np.mean(records)), 2)}


if __name__ == "__main__":
    main()
