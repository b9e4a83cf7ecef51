"""Latency of the local motion path: trajectory construction, command submission, self-collision check.

construction  TrajectoryBuilder.build(keyframes, d, q_last) for every library sequence x intensity 1-5
              (Eq. intensity applied first, not timed), from the neutral pose: the paper's path
timed         TrajectoryBuilder.build_timed(...) of the same gestures placed by the timeline (a lone
              gesture, its word 1 s in; the plan itself not timed): what the default schedule builds
submission    Sequencer.submit(GestureCommand) on a dry_run loop (the paper's non-blocking hand-off)
collision     SelfCollisionChecker.check(samples) on each constructed trajectory (the sequencer's safety
              hook, timed separately because the paper's construction figure does not include it)
Each case is repeated --repeats times after one warm-up; mean / p95 / max in ms.
Run: python benchmarks/construction.py [--repeats 20] [--rt-priority 50]  -> JSON on stdout.
On a loaded machine the p95 is set by preemption, not by the code: --rt-priority runs it SCHED_FIFO, as
the robot-side process would run.
"""

from __future__ import annotations

import argparse
import gc
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout without installing

from control_loop import realtime_priority  # benchmarks/ is on sys.path when run as a script

from emopose.backends.dry_run import DryRunBackend
from emopose.clock import FakeClock
from emopose.contract import GestureRecord
from emopose.execution.control_loop import ControlLoop
from emopose.execution.gesture_command import GestureCommand
from emopose.execution.sequencer import Sequencer
from emopose.execution.trajectory import TrajectoryBuilder
from emopose.library import MotionLibrary
from emopose.robot.collision import SelfCollisionChecker
from emopose.stages.modulate import modulate_keyframes
from emopose.turn.model import ModulatedGesture, ResolvedGesture
from emopose.turn.timeline import TimelinePlanner, TimelineSettings

LIBRARY = Path(__file__).resolve().parents[1] / "library" / "g1"


def stats(seconds: list[float]) -> dict:
    ms = np.asarray(seconds) * 1e3
    return {"mean": float(ms.mean()), "p50": float(np.percentile(ms, 50)),
            "p95": float(np.percentile(ms, 95)), "max": float(ms.max()), "n": int(ms.size)}


def timed(fn, *args) -> tuple[float, object]:
    start = time.perf_counter()
    out = fn(*args)
    return time.perf_counter() - start, out


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--repeats", type=int, default=20)
    parser.add_argument("--library", default=str(LIBRARY))
    parser.add_argument("--rt-priority", type=int, default=0,
                        help="SCHED_FIFO priority (0 = normal scheduling)")
    args = parser.parse_args()
    scheduling = realtime_priority(args.rt_priority)
    library = MotionLibrary.from_config(paths=[args.library], limits=str(Path(args.library) / "limits.yaml"))
    builder, checker = TrajectoryBuilder(library.limits), SelfCollisionChecker()
    neutral = library.neutral_entry.q[0]
    cases = [(e, level, modulate_keyframes(e.q, level, library.limits))
             for e in library.snapshot.entries.values() if e.motion_type == "sequence"
             for level in range(1, 6)]
    build_s, check_s, per_motion = [], [], {}
    gc.disable()  # a collection pause is not construction time; reported separately below if it mattered
    for entry, _level, keyframes in cases:
        builder.build(keyframes, entry.default_duration, neutral)  # warm-up
        for _ in range(args.repeats):
            dt, trajectory = timed(builder.build, keyframes, entry.default_duration, neutral)
            build_s.append(dt)
            per_motion.setdefault(entry.name, []).append(dt)
            check_s.append(timed(checker.check, trajectory.samples)[0])
    planner, timed_s = TimelinePlanner(builder, TimelineSettings()), []
    for entry, level, keyframes in cases:
        record = GestureRecord(cls=entry.cls, variant=entry.name, intensity=level)
        gesture = ModulatedGesture(ResolvedGesture(record, entry, "exact"), keyframes, entry.default_duration)
        (timing,), _ = planner.plan([gesture], [1.0])
        times = np.asarray(timing.times[1:]) - timing.times[0]
        builder.build_timed(timing.keyframes, times, neutral)  # warm-up
        timed_s += [timed(builder.build_timed, timing.keyframes, times, neutral)[0]
                    for _ in range(args.repeats)]
    # Submission: the hand-off into the queue, with a loop ticking between submissions as in a session.
    sequencer = Sequencer(builder, neutral)
    loop = ControlLoop(sequencer, DryRunBackend(), FakeClock())
    loop.begin(neutral)
    submit_s = []
    for entry, _, keyframes in cases * args.repeats:
        command = GestureCommand(entry.name, keyframes, entry.default_duration)
        submit_s.append(timed(sequencer.submit, command)[0])
        loop.tick()
        if len(sequencer.pending) > 4:
            sequencer.interrupt((), now=None)  # keep the queue short, like real replies
    gc.enable()
    slowest = max(per_motion, key=lambda n: np.percentile(per_motion[n], 95))
    print(json.dumps({
        "motions": len({e.name for e, _, _ in cases}), "cases": len(cases), "repeats": args.repeats,
        "scheduling": scheduling, "load_avg_1min": os.getloadavg()[0],
        "construction_ms": stats(build_s),
        "timed_construction_ms": stats(timed_s),
        "submission_ms": stats(submit_s),
        "collision_check_ms": stats(check_s),
        "slowest_motion": {"name": slowest, **stats(per_motion[slowest])},
        "target": {"construction_p95_ms": 0.10, "submission_p95_ms": 0.05},
    }, indent=2))


if __name__ == "__main__":
    main()
