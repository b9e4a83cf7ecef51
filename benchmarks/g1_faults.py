"""Wall-clock fault windows of the G1 backend against the fake robot on loopback (real DDS 0.10.2).

    python benchmarks/g1_faults.py [--trials 5] [--domain-id N]

The tests check the bounds in virtual time (tests/backends/g1/test_g1_faults.py, test_g1_release.py);
this measures how long the real thing takes on this machine, where the supervisor's polling and the
scheduler add to the bound. Prints one JSON object, for each fault, the delay (ms) from its cause to the
backend's release decision:
  lowstate_loss  fake robot SIGKILLed mid-stream (the sequencer keeps sending) -> failure set;
                 bound lowstate_loss_ms = 200
  deadman        last send() of a stream, then silence -> failure set; bound deadman_ms = 100
and, per injected stall (50-400 ms, in the ramp-up, the stream and the release, each trial), what the
fake robot received, by the DDS source timestamps: the smallest gap between two commands (>= 10 ms, half
a period), the most in any 100 ms (5 on the grid, 6 with the one half a period after a stall), and the
largest per-tick change of kd * dq* + tau in the release, which starts mid-motion (bound 0.5 N m).
"""

from __future__ import annotations

import argparse
import json
import os
import random
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from g1_publish import start_fake  # noqa: E402  (this folder is on sys.path when run as a script)

from emopose.backends.g1 import G1Backend  # noqa: E402
from emopose.backends.g1.release import MAX_EFFORT_STEP_NM  # noqa: E402
from emopose.clock import MonotonicClock  # noqa: E402
from emopose.execution.pacing import DeadlineGrid  # noqa: E402
from emopose.recording import Recorder, read_recording  # noqa: E402
from emopose.robot.g1_spec import CONTROL_DT  # noqa: E402

STALLS_S = (0.05, 0.1, 0.2, 0.4)
LAW = {"kp": 60.0, "kd": 1.5, "velocity_feedforward": True, "gravity_compensation": True}

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


class StallingClock(MonotonicClock):
    """Wall time in which one chosen sleep overruns: the process stalls there for real."""

    def __init__(self) -> None:
        self.stall: tuple[float, float] | None = None  # (not before, seconds)

    def sleep_until(self, deadline: float) -> None:
        super().sleep_until(deadline)
        if self.stall is not None and self.now() >= self.stall[0]:
            time.sleep(self.stall[1])
            self.stall = None


def stalled_run(domain_id: int, stall_s: float, folder: Path) -> dict:
    """Ramp-up, 1 s of a fast stream, release, one stall in each; what the fake robot received."""
    folder.mkdir()
    log = folder / "fake.jsonl"
    fake = start_fake(domain_id, "--log", str(log))
    clock = StallingClock()
    recorder = Recorder(folder / "run.mcap", clock=clock)  # which phase each command belongs to
    backend = G1Backend(domain_id=domain_id, clock=clock, **{**FAST, "deadman_ms": 1000, **LAW})
    try:
        clock.stall = (clock.now() + 0.3, stall_s)
        q0 = backend.connect(recorder)
        clock.stall = (clock.now() + 0.4, stall_s)
        grid = DeadlineGrid(clock, CONTROL_DT)
        while (t := grid.wait() - grid.t0) < 1.0 or np.cos(8.0 * t) < 0.9:
            backend.send(t, q0 + 0.3 * np.sin(8.0 * t))
            grid.sent()
        clock.stall = (clock.now() + 0.1, stall_s)
        backend.close()
    finally:
        backend.close()
        recorder.close()
        fake.terminate()
        fake.wait(timeout=5)
    phases = [p["phase"] for _, p in read_recording(folder / "run.mcap")["/g1/lowcmd"]]
    arm = [json.loads(line) for line in log.read_text().splitlines() if '"kind": "arm"' in line]
    if len(arm) != len(phases):
        raise SystemExit(f"the fake robot heard {len(arm)} of {len(phases)} commands")
    sent = np.array([a["sent_ns"] for a in arm]) / 1e9
    effort = np.array([LAW["kd"] * np.array(a["dq"]) + np.array(a["tau"]) for a in arm])
    first = phases.index("release")  # from the last stream command on
    return {"min_gap_ms": float(np.diff(sent).min() * 1e3),
            "max_in_100ms": int((np.searchsorted(sent, sent + 0.1) - np.arange(len(sent))).max()),
            "release_effort_step_nm": float(np.abs(np.diff(effort[first - 1:], axis=0)).max())}


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
    with tempfile.TemporaryDirectory() as folder:
        stalls = {f"{stall * 1e3:.0f}ms": [stalled_run(args.domain_id, stall, Path(folder) / f"{stall}_{k}")
                                           for k in range(args.trials)] for stall in STALLS_S}
    worst = {key: {"min_gap_ms": round(min(r["min_gap_ms"] for r in runs), 2),
                   "max_in_100ms": max(r["max_in_100ms"] for r in runs),
                   "release_effort_step_nm_max": round(max(r["release_effort_step_nm"] for r in runs), 3)}
             for key, runs in stalls.items()}
    print(json.dumps({"benchmark": "g1_faults", "cpus": os.cpu_count(),
                      "lowstate_loss": stats(loss, FAST["lowstate_loss_ms"]),
                      "deadman": stats(deadman, FAST["deadman_ms"]),
                      "stalls": {"bound_min_gap_ms": CONTROL_DT / 2 * 1e3,
                                 "bound_effort_step_nm": MAX_EFFORT_STEP_NM, **worst}}, indent=2))


if __name__ == "__main__":
    main()
