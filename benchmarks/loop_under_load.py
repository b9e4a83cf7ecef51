"""The real-time loop's lateness when its process's other threads want the GIL and other processes want
the CPU: the priority inversion through the GIL, and what each process scheduling does against it.

Runs ControlLoop (dry_run, MonotonicClock, run.rt_priority's SCHED_FIFO for the loop thread) for
--seconds while --threads Python threads of the same process do server-like work (JSON round trips with
short sleeps, as a web server pushing to pages does) and --busy other processes spin. Each --scheduling:
  rr    the process's other threads in SCHED_RR below the loop (what real-time runs do)
  nice  the process's other threads at nice PROCESS_NICE (the previous policy)
Reports per scheduling: ticks, missed deadlines, stalls, lateness p99 / p99.9 / max and the ticks over 20
ms late (a gap over 40 ms between commands needs one over 40). Needs permission for real-time scheduling.
Run: python benchmarks/loop_under_load.py [--seconds 20] [--busy 3] [--threads 3] [--rounds 2]  -> JSON.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # run from a checkout without installing

from emopose.backends.dry_run import DryRunBackend
from emopose.clock import MonotonicClock
from emopose.execution import control_loop, priority
from emopose.execution.control_loop import ControlLoop
from emopose.execution.sequencer import Sequencer
from emopose.execution.trajectory import TrajectoryBuilder
from emopose.library import MotionLibrary

LIBRARY = ROOT / "library" / "g1"


def server_like(stop: threading.Event) -> None:
    payload = {"cues": list(range(200)), "text": "x" * 200}
    while not stop.is_set():
        for _ in range(200):
            json.loads(json.dumps(payload))
        time.sleep(0.002)


def reniced() -> str:
    """The previous policy: every thread at nice PROCESS_NICE."""
    for thread in os.listdir("/proc/self/task"):
        os.setpriority(os.PRIO_PROCESS, int(thread), priority.PROCESS_NICE)
    return f"process nice {priority.PROCESS_NICE}"


def run_once(scheduling: str, seconds: float, threads: int, library: MotionLibrary) -> dict:
    rest = np.asarray(library.neutral_entry.q[0], dtype=float)
    clock = MonotonicClock()
    loop = ControlLoop(Sequencer(TrajectoryBuilder(library.limits), rest), DryRunBackend(), clock)
    loop.begin(rest)
    control_loop.raise_process_priority = priority.raise_process_priority if scheduling == "rr" else reniced
    stop = threading.Event()
    loop.start(10)
    workers = [threading.Thread(target=server_like, args=(stop,), daemon=True) for _ in range(threads)]
    for worker in workers:
        worker.start()
    time.sleep(seconds)
    loop.stop()
    stop.set()
    priority.normal_scheduling()
    for thread in os.listdir("/proc/self/task"):
        os.setpriority(os.PRIO_PROCESS, int(thread), 0)
    late = np.asarray(list(loop.stats.lateness_s)) * 1e3
    s = loop.stats.summary()
    return {"scheduling": s["scheduling"], "ticks": s["ticks"], "missed": s["missed_deadlines"],
            "stalls": s["stalls"], "late_ms_p99": float(np.percentile(late, 99)),
            "late_ms_p999": float(np.percentile(late, 99.9)), "late_ms_max": s["lateness_ms_max"],
            "ticks_over_20ms_late": int((late > 20).sum())}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--busy", type=int, default=3, help="other processes spinning the whole time")
    parser.add_argument("--threads", type=int, default=3, help="server-like threads in the loop's process")
    parser.add_argument("--rounds", type=int, default=2, help="each scheduling this often, interleaved")
    args = parser.parse_args()
    library = MotionLibrary.from_config(paths=[str(LIBRARY)], limits=str(LIBRARY / "limits.yaml"))
    spinners = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(args.busy)]
    try:
        rows = [run_once(name, args.seconds, args.threads, library)
                for _ in range(args.rounds) for name in ("rr", "nice")]
    finally:
        for spinner in spinners:
            spinner.kill()
    print(json.dumps({"busy": args.busy, "threads": args.threads, "seconds": args.seconds,
                      "load_1min": os.getloadavg()[0], "rows": rows}, indent=1))


if __name__ == "__main__":
    main()
