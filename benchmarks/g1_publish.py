"""Benchmark the G1 backend's publish path against the fake robot on loopback (real DDS 0.10.2).

    python benchmarks/g1_publish.py [--seconds 60] [--messages 5000] [--domain-id N] [--arm-law robot]

Prints one JSON object:
  latency: per-message cost of build+CRC+write over --messages back-to-back commands on a DDS
           link of its own (G1Link, microseconds): the backend itself paces its commands at least
           half a period apart, so it cannot be driven back to back;
  period:  a 50 Hz loop driven by absolute deadlines (MonotonicClock.sleep_until) for
           --seconds: error of each publication interval against 20 ms (p50/p99/max, ms),
           how late each send started after its deadline, and what each G1Backend.send() call
           cost (validate, clamp, lock, build, CRC, write, record).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import random
import subprocess
import sys
import time
from importlib import metadata
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from omegaconf import OmegaConf

from emopose.backends.g1 import G1Backend
from emopose.backends.g1.settings import G1Settings
from emopose.clock import MonotonicClock


def stats_us(samples: list[float]) -> dict:
    a = np.asarray(samples) * 1e6
    return {
        "mean": round(float(a.mean()), 2),
        "p50": round(float(np.percentile(a, 50)), 2),
        "p95": round(float(np.percentile(a, 95)), 2),
        "p99": round(float(np.percentile(a, 99)), 2),
        "max": round(float(a.max()), 2),
    }


def stats_ms(samples: np.ndarray) -> dict:
    a = np.abs(samples) * 1e3
    return {
        "p50": round(float(np.percentile(a, 50)), 4),
        "p99": round(float(np.percentile(a, 99)), 4),
        "max": round(float(a.max()), 4),
    }


def start_fake(domain_id: int, *extra: str) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": f"{REPO}{os.pathsep}{os.environ.get('PYTHONPATH', '')}"}
    proc = subprocess.Popen(
        [sys.executable, "-m", "emopose.testing.fake_robot", "--domain-id", str(domain_id), *extra],
        cwd=REPO,
        env=env,
        stdout=subprocess.PIPE,
        text=True,
    )
    if proc.stdout.readline().strip() != "READY":
        proc.kill()
        raise SystemExit("fake robot did not start")
    return proc


def measure_link(settings: G1Settings, n: int) -> dict:
    """The DDS link alone (build + CRC + write), on its own participant."""
    from emopose.backends.g1.link import G1Link

    link = G1Link(settings, time.perf_counter)
    try:
        q0 = link.wait_for_robot()
        poses = q0[None, :] + 0.05 * np.sin(np.arange(n)[:, None] / 25.0)
        link_s = []
        for i in range(n):
            t0 = time.perf_counter()
            link.publish(poses[i], 0.0, *link.feedforward(poses[i]))  # weight 0: the fake keeps its pose
            link_s.append(time.perf_counter() - t0)
    finally:
        link.close()
    return {"messages": n, "build_crc_write_us": stats_us(link_s)}


def measure_period(backend: G1Backend, q0: np.ndarray, seconds: float) -> dict:
    clock, dt = MonotonicClock(), 0.02
    n = round(seconds / dt)
    stamps, late, send_s = np.empty(n), np.empty(n), []
    deadline = clock.now()
    for k in range(n):
        deadline += dt
        clock.sleep_until(deadline)
        start = clock.now()
        backend.send(k * dt, q0 + 0.05 * np.sin(k / 25.0))
        send_s.append(clock.now() - start)
        stamps[k], late[k] = start, start - deadline
    return {
        "seconds": seconds,
        "ticks": n,
        "period_error_ms": stats_ms(np.diff(stamps) - dt),
        "deadline_lateness_ms": stats_ms(late),
        "send_us": stats_us(send_s),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seconds", type=float, default=60.0, help="length of the 50 Hz run")
    parser.add_argument("--messages", type=int, default=5000, help="messages for the latency run")
    parser.add_argument("--domain-id", type=int, default=random.SystemRandom().randint(20, 230))
    parser.add_argument("--arm-law", default="robot",
                        help="conf/arm_law/<name>.yaml: the gains and feed-forwards sent")
    args = parser.parse_args()
    law = OmegaConf.load(REPO / "conf" / "arm_law" / f"{args.arm_law}.yaml")
    fake = start_fake(args.domain_id)
    backend = G1Backend(
        domain_id=args.domain_id,
        lowstate_timeout_s=10.0,
        weight_ramp_down_s=1.0,
        release_blend_s=0.5,
        kp=law.kp,
        kd=law.kd,
        velocity_feedforward=law.velocity_feedforward,
        gravity_compensation=law.gravity_compensation,
    )
    try:
        latency = measure_link(backend.settings, args.messages)
        q0 = backend.connect(None)
        period = measure_period(backend, q0, args.seconds)
        status = backend.status()
    finally:
        backend.close()
        fake.terminate()
        fake.wait(timeout=5)
    print(
        json.dumps(
            {
                "benchmark": "g1_publish",
                "transport": "Cyclone DDS loopback, fake robot in a separate process",
                "cyclonedds": metadata.version("cyclonedds"),
                "python": platform.python_version(),
                "cpus": os.cpu_count(),
                "arm_law": law.name,
                "latency": latency,
                "period_50hz": period,
                "lowstate_seen": status["lowstate_valid"],
                "failure": status["failure"],
            },
            indent=2,
        )
    )


if __name__ == "__main__":
    main()
