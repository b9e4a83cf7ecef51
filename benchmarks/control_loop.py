"""The real 50 Hz control loop in wall time: period error, cumulative drift and missed deadlines.

Runs emopose.execution.control_loop.ControlLoop with the MonotonicClock (absolute deadlines t0 + n dt) for
--seconds per backend (dry_run, mujoco), with the sequencer kept busy: a library motion is submitted
whenever it settles, so trajectory construction happens inside the loop as in a session.
  period error  (actual tick n - actual tick n-1) - dt, where "actual" is when sleep_until returned
  lateness      actual tick n - its ideal time t0 + n dt
  drift         lateness of the last tick (absolute deadlines keep it from accumulating) and the
                least-squares slope of lateness over the run (ms per minute)
  missed        ticks whose work (step + send) ended after the next deadline
Run: python benchmarks/control_loop.py [--seconds 60] [--backends dry_run mujoco]  -> JSON on stdout.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout without installing
os.environ.setdefault("MUJOCO_GL", "egl")

from emopose import CONTROL_DT
from emopose.clock import MonotonicClock
from emopose.execution.control_loop import ControlLoop
from emopose.execution.gesture_command import GestureCommand
from emopose.execution.sequencer import Sequencer
from emopose.execution.trajectory import TrajectoryBuilder
from emopose.library import MotionLibrary

LIBRARY = Path(__file__).resolve().parents[1] / "library" / "g1"


def make_backend(name: str):
    if name == "dry_run":
        from emopose.backends.dry_run import DryRunBackend

        return DryRunBackend()
    from emopose.backends.mujoco import MujocoBackend

    return MujocoBackend()


class TimedClock(MonotonicClock):
    """MonotonicClock that remembers when each sleep_until returned (the tick's actual start)."""

    def __init__(self) -> None:
        self.woke: list[float] = []

    def sleep_until(self, deadline: float) -> None:
        super().sleep_until(deadline)
        self.woke.append(time.perf_counter())


def run(backend_name: str, seconds: float, library: MotionLibrary) -> dict:
    clock = TimedClock()
    neutral = library.neutral_entry.q[0]
    sequencer = Sequencer(TrajectoryBuilder(library.limits), neutral)
    backend = make_backend(backend_name)
    backend.connect(None)
    loop = ControlLoop(sequencer, backend, clock)
    motions = [e for e in library.snapshot.entries.values() if e.motion_type == "sequence"]
    loop.begin(neutral)
    t0, ticks = clock.now() - loop.stream_time, round(seconds / CONTROL_DT)
    done_at = np.empty(ticks)
    for n in range(ticks):
        if sequencer.settled():  # keep it busy: the next motion as soon as the last one ends
            entry = motions[n % len(motions)]
            sequencer.submit(GestureCommand(entry.name, entry.q, entry.default_duration))
        loop.tick()
        done_at[n] = time.perf_counter()
    backend.close()
    woke = np.array(clock.woke)
    ideal = t0 + CONTROL_DT * np.arange(1, ticks + 1)
    late_ms = (woke - ideal) * 1e3
    period_ms = np.abs(np.diff(woke) - CONTROL_DT) * 1e3
    slope = np.polyfit((ideal - t0) / 60.0, late_ms, 1)[0]
    work_ms = (done_at - woke) * 1e3
    return {
        "backend": backend_name, "seconds": seconds, "ticks": ticks,
        "period_error_ms": {"p50": float(np.percentile(period_ms, 50)),
                            "p99": float(np.percentile(period_ms, 99)), "max": float(period_ms.max())},
        "lateness_ms": {"p50": float(np.percentile(late_ms, 50)), "p99": float(np.percentile(late_ms, 99)),
                        "max": float(late_ms.max())},
        "cumulative_drift_ms": float(late_ms[-1]),
        "drift_slope_ms_per_min": float(slope),
        "work_ms": {"p50": float(np.percentile(work_ms, 50)), "p99": float(np.percentile(work_ms, 99)),
                    "max": float(work_ms.max())},
        "missed_deadlines": int(np.sum(done_at > ideal + CONTROL_DT)),
        # deadlines ControlLoop skipped after falling behind
        "loop_missed_deadlines": loop.stats.missed_deadlines,
        "motions_started": sum(e.kind == "started" for e in sequencer.events),
    }


def realtime_priority(priority: int) -> str:
    """SCHED_FIFO for this process, as a robot-side control loop would run; needs root or CAP_SYS_NICE."""
    if priority <= 0:
        return "SCHED_OTHER (not requested)"
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
        return f"SCHED_FIFO {priority}"
    except (AttributeError, PermissionError, OSError) as exc:
        return f"SCHED_OTHER ({exc.__class__.__name__}: could not get SCHED_FIFO)"


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--backends", nargs="+", default=["dry_run", "mujoco"], choices=["dry_run", "mujoco"])
    parser.add_argument("--library", default=str(LIBRARY))
    parser.add_argument("--rt-priority", type=int, default=0,
                        help="SCHED_FIFO priority (0 = normal scheduling)")
    args = parser.parse_args()
    library = MotionLibrary.from_config(paths=[args.library], limits=str(Path(args.library) / "limits.yaml"))
    scheduling = realtime_priority(args.rt_priority)
    load_before = os.getloadavg()[0]
    results = [run(name, args.seconds, library) for name in args.backends]
    target = {"period_error_p99_ms": 2.0, "cumulative_drift_ms": 0.0}
    print(json.dumps({"target": target, "cpus": os.cpu_count(), "scheduling": scheduling,
                      "load_avg_1min": [load_before, os.getloadavg()[0]], "results": results}, indent=2))


if __name__ == "__main__":
    main()
