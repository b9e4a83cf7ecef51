"""Web UI simulation view: frames per second the MuJoCo view renderer sustains (target >= 10 fps).

    MUJOCO_GL=egl python benchmarks/web_frames.py [--seconds 10]
Renders the 'front' camera (and the inset 'head' camera every other frame, as the UI does with its
default rates) at 320x240 through emopose.web.pose_renderer with a moving arm pose. Prints JSON.
"""

from __future__ import annotations

import argparse
import json
import os
import time

import numpy as np

os.environ.setdefault("MUJOCO_GL", "egl")

from emopose.web.pose_renderer import PoseRenderer


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--seconds", type=float, default=10.0)
    args = parser.parse_args()
    renderer = PoseRenderer()
    if not renderer.start():
        print(json.dumps({"error": renderer.error}))
        return
    frame_ms, frames, started = [], 0, time.perf_counter()
    while time.perf_counter() - started < args.seconds:
        q = np.zeros(14)
        q[7] = -1.0 + 0.5 * np.sin(frames / 10)  # right shoulder pitch sweeps
        t0 = time.perf_counter()
        renderer.render_jpeg(q=q, camera="front")
        frame_ms.append((time.perf_counter() - t0) * 1e3)
        if frames % 2 == 0:
            renderer.render_jpeg(q=q, camera="head")
        frames += 1
    elapsed = time.perf_counter() - started
    ms = np.asarray(frame_ms)
    print(json.dumps({"sim_view_fps": round(frames / elapsed, 1), "front_frame_ms": {
        "p50": round(float(np.median(ms)), 1), "p95": round(float(np.percentile(ms, 95)), 1)},
        "with_head_inset_every_other_frame": True, "load_avg_1min": round(os.getloadavg()[0], 2)}))


if __name__ == "__main__":
    main()
