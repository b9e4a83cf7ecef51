"""Memory soak of serve: one turn a second for --minutes with --watchers pages open.

Starts `python -m emopose +experiment=serve` (dry_run, keyword planner, recording on, no MuJoCo frames
unless --extra says otherwise) on a free port, opens --watchers WebSocket pages (benchmarks/live_serve.py
`watch`), says one sequence-suite text a second through /api/say and samples the server's RSS (VmRSS
of its process) every 10 s. Stops it with SIGTERM and reads results.json and session.mcap.
Reports: RSS at the start, after the warm-up (the first quarter, at most 5 minutes) and at the end, and
its growth per minute after the warm-up; say latency quartiles in the first and the last quarter of the
turns (p95 ratio last/first); the history (window, messages, dropped turns, results.json) and the
/request and /dialogue record sizes (session.mcap); whether results.json counted every turn sent.
Targets (issue 30, 20 minutes, 4 watchers): RSS growth < 20 MB after the first 5 minutes, last-quarter
p95 within 1.2x of the first, history and /request size bounded.
Run: python benchmarks/serve_soak.py [--minutes 20] [--watchers 4] [--extra key=value ...] -> JSON
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from live_serve import ROOT, SUITE, call, free_port, wait_ready, watch  # noqa: E402
from run_dirs import measure_and_print  # noqa: E402

from emopose.recording import read_recording  # noqa: E402


def rss_mb(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    raise RuntimeError(f"no VmRSS for process {pid}")


def quartiles_ms(values: list[float]) -> dict:
    q = np.percentile(np.asarray(values) * 1e3, [25, 50, 75, 95])
    return {"n": len(values), **{f"p{p}_ms": round(float(v), 1) for p, v in zip((25, 50, 75, 95), q)}}


def drive(port: int, pid: int, minutes: float) -> tuple[list[float], list[tuple[float, float]]]:
    """One /api/say a second (the next waits for the slot, never for the robot); RSS every 10 s."""
    texts = [json.loads(line)["text"] for line in SUITE.read_text().splitlines() if line.strip()]
    latencies, rss, started = [], [], time.monotonic()
    turn = 0
    while (elapsed := time.monotonic() - started) < minutes * 60:
        if not rss or elapsed - rss[-1][0] >= 10:
            rss.append((elapsed, rss_mb(pid)))
        sent = time.perf_counter()
        call(port, "/api/say", {"text": texts[turn % len(texts)]})
        latencies.append(time.perf_counter() - sent)
        turn += 1
        time.sleep(max(0.0, started + turn - time.monotonic()))
    rss.append((time.monotonic() - started, rss_mb(pid)))
    return latencies, rss


def memory(rss: list[tuple[float, float]], minutes: float) -> dict:
    warm_s = min(300.0, minutes * 15)  # a quarter of the run, at most 5 minutes
    after = [(t, m) for t, m in rss if t >= warm_s] or rss[-1:]
    slope = np.polyfit([t for t, _ in after], [m for _, m in after], 1)[0] * 60 if len(after) > 2 else 0.0
    return {"start_mb": round(rss[0][1], 1), "after_warmup_mb": round(after[0][1], 1),
            "end_mb": round(rss[-1][1], 1), "growth_after_warmup_mb": round(rss[-1][1] - after[0][1], 1),
            "growth_mb_per_min_after_warmup": round(float(slope), 3), "warmup_s": warm_s}


def record_sizes(mcap: Path) -> dict:
    recording = read_recording(mcap)
    sizes = [len(json.dumps(payload)) for _, payload in recording.get("/request", [])]
    history = [payload["history_messages"] for _, payload in recording.get("/request", [])]
    return {"request_bytes_max": max(sizes),
            "request_bytes_first_quarter_max": max(sizes[:len(sizes) // 4 + 1]),
            "history_messages_max": max(history), "dialogue_messages": len(recording.get("/dialogue", []))}


def measure(args: argparse.Namespace, run_dir: Path) -> dict:
    port = free_port()
    env = {**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl"), "HF_HUB_OFFLINE": "1"}
    command = [sys.executable, "-m", "emopose", "+experiment=serve", "planner=keyword", "job.render=false",
               f"serve.port={port}", f"hydra.run.dir={run_dir}", *args.extra]
    with open(run_dir / "serve.log", "w") as log:
        server = subprocess.Popen(command, cwd=ROOT, env=env, stdout=subprocess.DEVNULL, stderr=log)
    stop = threading.Event()
    try:
        wait_ready(port, server)
        for _ in range(args.watchers):
            threading.Thread(target=watch, args=(port, stop), daemon=True).start()
        latencies, rss = drive(port, server.pid, args.minutes)
    finally:
        stop.set()
        server.send_signal(signal.SIGTERM)
        server.wait(timeout=120)
    results = json.loads((run_dir / "results.json").read_text())
    quarter = max(1, len(latencies) // 4)
    first, last = quartiles_ms(latencies[:quarter]), quartiles_ms(latencies[-quarter:])
    return {"command": " ".join(command[1:]), "minutes": args.minutes, "watchers": args.watchers,
            "turns_sent": len(latencies), "turns_counted": results["turns"], "exit_status": server.returncode,
            "rss": memory(rss, args.minutes), "say_first_quarter": first, "say_last_quarter": last,
            "say_p95_ratio_last_first": round(last["p95_ms"] / first["p95_ms"], 2),
            "history": results["history"], **record_sizes(run_dir / "session.mcap")}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--minutes", type=float, default=20.0)
    parser.add_argument("--watchers", type=int, default=4, help="WebSocket pages open the whole time")
    parser.add_argument("--extra", nargs="*", default=[], help="more overrides for the serve command")
    parser.add_argument("--run-dir", type=Path, default=None, help="keep the run here (default: a temp dir)")
    measure_and_print(measure, parser.parse_args(), "emopose-soak-")


if __name__ == "__main__":
    main()
