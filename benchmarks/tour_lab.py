"""The four-stop lab tour in wall time: how long +experiment=tour_lab takes and how much faster than
real time it runs (targets: <= 300 s wall, real-time factor > 1: simulated seconds per wall second).

The tour runs on a virtual clock in MuJoCo and ticks the 50 Hz loop itself, so wall time is physics,
planning and the 2 fps video rendering; it says how loaded the machine is as much as anything.
tests/tour/test_tour_lab.py checks the tour's outcome and its simulated time, not these figures.
Run: MUJOCO_GL=egl python benchmarks/tour_lab.py [Hydra overrides, e.g. planner=keyword job.video=false]
-> JSON on stdout (the tour's own report goes to stdout first).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
from pathlib import Path

from hydra import compose, initialize_config_dir

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout without installing
os.environ.setdefault("MUJOCO_GL", "egl")

from emopose.app import run
from emopose.config import CONFIG_DIR

TARGET_WALL_S = 300.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("overrides", nargs="*", help="Hydra overrides added to +experiment=tour_lab")
    args = parser.parse_args()
    with initialize_config_dir(config_dir=str(CONFIG_DIR), version_base="1.3"):
        cfg = compose("config", overrides=["+experiment=tour_lab", *args.overrides])
    with tempfile.TemporaryDirectory() as run_dir:
        results = run(cfg, Path(run_dir))
    wall_s, sim_s = results["wall_time_s"], results["sim_time_s"]
    print(json.dumps({"overrides": args.overrides, "wall_time_s": round(wall_s, 1),
                      "sim_time_s": round(sim_s, 1), "realtime_factor": round(sim_s / wall_s, 2),
                      "target_wall_s": TARGET_WALL_S,
                      "within_target": wall_s <= TARGET_WALL_S and sim_s > wall_s,
                      "stops_reached": results["stops_reached"],
                      "load_avg_1min": round(os.getloadavg()[0], 2)},
                     indent=2))


if __name__ == "__main__":
    main()
