"""Wall time of one MujocoBackend.send(): one 20 ms control period of physics (must be far below 20 ms).

Run: python benchmarks/mujoco_step.py [--ticks 2000] [--substeps N]   -> JSON on stdout.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(
    0, str(Path(__file__).resolve().parents[1])
)  # run from a checkout without installing

from emopose import CONTROL_DT
from emopose.backends.mujoco import MujocoBackend

CENTER = np.array([-0.4, 0.45, 0, 0.9, 0, 0, 0, -0.4, -0.45, 0, 0.9, 0, 0, 0])


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--ticks", type=int, default=2000)
    parser.add_argument("--substeps", type=int, default=None)
    args = parser.parse_args()

    phase = np.linspace(0, 2 * np.pi, 14, endpoint=False)
    # Start on the trajectory so the first tick is not a step.
    backend = MujocoBackend(
        initial_pose=(CENTER + 0.3 * np.sin(phase)).tolist(), substeps=args.substeps
    )
    backend.connect(None)
    times, errors = [], []
    for k in range(args.ticks):
        t = k * CONTROL_DT
        q = CENTER + 0.3 * np.sin(2 * np.pi * 0.5 * t + phase)
        start = time.perf_counter()
        backend.send(t, q)
        times.append(time.perf_counter() - start)
        if t >= 0.5:
            errors.append(np.abs(backend.measured() - q))
    backend.close()
    ms = np.array(times[50:]) * 1e3  # skip warm-up ticks
    print(
        json.dumps(
            {
                "ticks": args.ticks,
                "substeps": backend.n_substeps,
                "timestep_s": backend.model.opt.timestep,
                "send_median_ms": round(float(np.median(ms)), 4),
                "send_p95_ms": round(float(np.percentile(ms, 95)), 4),
                "send_max_ms": round(float(ms.max()), 4),
                "control_period_ms": CONTROL_DT * 1e3,
                "realtime_factor": round(CONTROL_DT * 1e3 / float(np.median(ms)), 1),
                "sine_tracking_mae_rad": round(float(np.mean(errors)), 5),
                "max_actuator_force_ratio": round(backend.max_actuator_force_ratio, 3),
            },
            indent=2,
        )
    )


if __name__ == "__main__":
    main()
