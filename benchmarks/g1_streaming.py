"""Streaming runs of backend=g1 against the fake robot under load: does the 100 ms deadman ever trip?

Issue 28's target: no deadman trip in 20 streaming runs of `backend=g1` against emopose.testing.fake_robot
with one core, and with both cores, kept busy by other processes. Each run is a whole
`python -m emopose +experiment=plan backend=g1 planner=PLANNER utterance=TEXT` process (the product's
default planner unless --planner says otherwise: its process is the size a user's is), against a fresh
fake robot on loopback (real DDS 0.10.2), with --busy processes spinning the whole time. Per run: the exit
status, the fault (results.json `fault`: "deadman: ..." is a trip), the loop's missed deadlines and the
largest gap between the commands the backend recorded (/joints/command) and the fake robot's log.
Run: python benchmarks/g1_streaming.py [--runs 20] [--busy 1] [--planner local] -> JSON on stdout.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from g1_publish import start_fake  # noqa: E402
from live_serve import ROOT, busy_cores, command_gaps  # noqa: E402

from emopose.recording import read_recording  # noqa: E402

TEXTS = ("Welcome! The workshop is through that door on the left.",
         "I'm so sorry, the café closed an hour ago, but the vending machines are just behind you.",
         "Absolutely, take as many leaflets as you like, they are free.",
         "No, no, please don't touch the robot arm while it is moving.")


def one_run(domain_id: int, planner: str, text: str, folder: Path) -> dict:
    fake = start_fake(domain_id)
    env = {**os.environ, "HF_HUB_OFFLINE": "1"}
    started = time.monotonic()
    try:
        done = subprocess.run([sys.executable, "-m", "emopose", "+experiment=plan", f"planner={planner}",
                               "backend=g1", f"backend.domain_id={domain_id}", f'utterance="{text}"',
                               f"hydra.run.dir={folder}"], cwd=ROOT, env=env, capture_output=True, text=True,
                              timeout=600)
    finally:
        fake.kill()
        fake.wait()
    results = json.loads((folder / "results.json").read_text()) if (folder / "results.json").exists() else {}
    fault = results.get("fault")
    loop = results.get("loop") or {}
    mcap = folder / "session.mcap"
    return {"exit": done.returncode, "wall_s": round(time.monotonic() - started, 1), "fault": fault,
            "deadman": bool(fault and fault.startswith("deadman")),
            "missed_deadlines": loop.get("missed_deadlines"), "ticks": loop.get("ticks"),
            **(command_gaps(read_recording(mcap)) if mcap.exists() else {}),
            **({} if done.returncode == 0 else {"stderr_tail": done.stderr[-400:]})}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=20)
    parser.add_argument("--busy", type=int, default=1, help="processes keeping a core busy throughout")
    parser.add_argument("--planner", default="local")
    parser.add_argument("--domain-id", type=int, default=random.SystemRandom().randint(20, 230))
    args = parser.parse_args()
    with busy_cores(args.busy), tempfile.TemporaryDirectory(prefix="g1_streaming_") as folder:
        runs = [one_run(args.domain_id, args.planner, TEXTS[k % len(TEXTS)], Path(folder) / f"run{k:02d}")
                for k in range(args.runs)]
    print(json.dumps({"runs": args.runs, "busy": args.busy, "planner": args.planner,
                      "deadman_trips": sum(r["deadman"] for r in runs),
                      "faults": sum(r["fault"] is not None for r in runs),
                      "failed_runs": sum(r["exit"] != 0 for r in runs),
                      "max_command_gap_ms": max(r.get("max_command_gap_ms", 0.0) for r in runs),
                      "missed_deadlines": sum(r["missed_deadlines"] or 0 for r in runs),
                      "ticks": sum(r["ticks"] or 0 for r in runs), "per_run": runs}, indent=2))


if __name__ == "__main__":
    main()
