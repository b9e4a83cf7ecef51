"""Local planner latency per utterance after load (target p95 <= 20 ms), over the bench texts.

    python benchmarks/local_planner.py [--items 480]
Prints JSON: load time, per-utterance latency mean/p50/p95/max in ms, records per plan.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from emopose.config import PROJECT_ROOT
from emopose.library import MotionLibrary
from emopose.planners.base import PlanRequest
from emopose.planners.local import LocalPlanner


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--items", type=int, default=480)
    args = parser.parse_args()
    lib_dir = PROJECT_ROOT / "library/g1"
    library = MotionLibrary.from_config(paths=[str(lib_dir)], limits=str(lib_dir / "limits.yaml"))
    started = time.perf_counter()
    planner = LocalPlanner(library, [str(PROJECT_ROOT / "experiments/train/train.jsonl"),
                                     str(PROJECT_ROOT / "experiments/train/train_sequences.jsonl")])
    load_s = time.perf_counter() - started
    texts = [json.loads(line)["text"] for line in
             Path(PROJECT_ROOT / "experiments/bench/emopose_bench.jsonl").read_text().splitlines()][: args.items]
    planner.plan(PlanRequest("Warm-up: hello there, look at that."))
    latencies, records = [], []
    for text in texts:
        output = planner.plan(PlanRequest(text))
        latencies.append(output.latency_s * 1e3)
        records.append(len(json.loads(output.raw)["gestures"]))
    ms = np.asarray(latencies)
    print(json.dumps({"items": len(texts), "load_s": round(load_s, 2),
                      "latency_ms": {"mean": round(float(ms.mean()), 2), "p50": round(float(np.median(ms)), 2),
                                     "p95": round(float(np.percentile(ms, 95)), 2), "max": round(float(ms.max()), 2)},
                      "records_per_plan_mean": round(float(np.mean(records)), 2)}, indent=2))


if __name__ == "__main__":
    main()
