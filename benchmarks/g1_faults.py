"""Wall-clock fault windows of the G1 backend against the fake robot on loopback (real DDS 0.10.2).

    python benchmarks/g1_faults.py [--trials 5] [--domain-id N]

The tests check the bounds in virtual time (tests/backends/g1/test_g1_faults.py); this measures
how long the real thing takes on this machine, where the supervisor's polling and the scheduler
add to the bound. Prints one JSON object, for each fault, the delay (ms) from its cause to the
backend's release decision:
  lowstate_loss  fake robot SIGKILLed mid-stream (the sequencer keeps sending) -> failure set;
                 bound lowstate_loss_ms = 200
  deadman        last send() of a stream, then silence -> failure set; bound deadman_ms = 100
"""

from __future__ import annotations

import argparse
import json
import os
import random
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from g1_publish import start_fake  # noqa: E402  (this folder is on sys.path when run as a script)

from emopose.backends.g1 import G1Backend  # noqa: E402
from emopose.robot.g1_spec import CONTROL_DT  # noqa: E402

FAST = {"lowstate_timeout_s": 10.0, "weight_ramp_up_s": 0.2, "weight_ramp_down_s": 0.4,
        "release_blend_s": 0.2, "lowstate_loss_ms": 200, "deadman_ms": 100}


def until_failure(backend: G1Backend, q0: np.ndarray, keep_sending: bool) -> tuple[float, float]:
    """Stream 10 ticks at 50 Hz, then (keep sending or not) poll every ms until the backend fails.
    Returns (time of the last send before the fault, time the failure was seen), perf_counter."""
    deadline, last_send, ticks = time.perf_counter(), 0.0, 0
    while backend.failure is None:
        now = time.perf_counter()
        if now >= deadline and (keep_sending or ticks < 10):
            try:
                backend.send(ticks * CONTROL_DT, q0)
            except Exception:  # noqa: BLE001 - the supervisor released between our check and send()
                break
            last_send, ticks, deadline = now, ticks + 1, deadline + CONTROL_DT
        time.sleep(0.001)
    return last_send, time.perf_counter()


def trial(domain_id: int, fault: str) -> float:
    fake = start_fake(domain_id)
    backend = G1Backend(domain_id=domain_id, **FAST)
    try:
        q0 = backend.connect(None)
        if fault == "lowstate_loss":
            for k in range(10):
                backend.send(k * CONTROL_DT, q0)
                time.sleep(CONTROL_DT)
            fake.kill()
            killed = time.perf_counter()
            _, seen = until_failure(backend, q0, keep_sending=True)
            return (seen - killed) * 1e3
        last_send, seen = until_failure(backend, q0, keep_sending=False)
        return (seen - last_send) * 1e3
    finally:
        backend.close()
        fake.kill()
        fake.wait(timeout=5)


def stats(delays: list[float], bound_ms: float) -> dict:
    a = np.asarray(delays)
    return {"bound_ms": bound_ms, "trials": len(a), "min_ms": round(float(a.min()), 2),
            "p50_ms": round(float(np.median(a)), 2), "max_ms": round(float(a.max()), 2),
            "over_bound_ms_max": round(float(a.max() - bound_ms), 2)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--trials", type=int, default=5)
    parser.add_argument("--domain-id", type=int, default=random.SystemRandom().randint(20, 230))
    args = parser.parse_args()
    loss = [trial(args.domain_id, "lowstate_loss") for _ in range(args.trials)]
    deadman = [trial(args.domain_id, "deadman") for _ in range(args.trials)]
    print(json.dumps({"benchmark": "g1_faults", "cpus": os.cpu_count(),
                      "lowstate_loss": stats(loss, FAST["lowstate_loss_ms"]),
                      "deadman": stats(deadman, FAST["deadman_ms"])}, indent=2))


if __name__ == "__main__":
    main()
