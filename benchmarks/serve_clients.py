"""Many pages at once: /api/health latency and each page's push rate with --pages WebSocket clients.

Starts `python -m emopose +experiment=serve` (dry_run, keyword planner, no MuJoCo frames unless --extra
says otherwise) on a free port with serve.max_clients = --cap, opens --pages WebSocket clients from one
asyncio thread (each counts the messages it receives), and while they watch asks /api/health every
50 ms and /api/say every 2 s, each on a fresh connection. Then reads the server's page counters
(/api/status "clients": open, refused, slowed) and stops it with SIGTERM.
Target (issue 30): 200 pages, /api/health p95 < 200 ms: `targets` judges it (and that every page up to the
cap was open), `pass` is both.
Run: python benchmarks/serve_clients.py [--pages 200] [--cap 250] [--seconds 30] [--extra key=value ...]
  -> JSON on stdout.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from live_serve import ROOT, call, free_port, wait_ready  # noqa: E402
from serve_soak import check  # noqa: E402

HEALTH_P95_BOUND_MS = 200.0  # issue 30, with 200 pages open


def serve_command(port: int, run_dir: Path, cap: int, extra: list[str]) -> list[str]:
    return [sys.executable, "-m", "emopose", "+experiment=serve", "planner=keyword", "job.render=false",
            "run.record=false", f"serve.port={port}", f"serve.max_clients={cap}",
            f"hydra.run.dir={run_dir}", *extra]


async def _page(port: int, stop: asyncio.Event, counts: list[int], closes: list[str]) -> None:
    from websockets.asyncio.client import connect
    from websockets.exceptions import ConnectionClosed

    index = len(counts)
    counts.append(0)
    try:
        async with connect(f"ws://127.0.0.1:{port}/ws", max_size=None, open_timeout=60) as websocket:
            while not stop.is_set():
                try:
                    await asyncio.wait_for(websocket.recv(), timeout=0.5)
                    counts[index] += 1
                except TimeoutError:
                    continue
    except ConnectionClosed as closed:
        closes.append(f"{closed.rcvd.code} {closed.rcvd.reason}" if closed.rcvd else "closed")


def pages(port: int, n: int, seconds: float, counts: list[int], closes: list[str]) -> threading.Thread:
    """n pages watching for `seconds` in one asyncio thread (started, not joined)."""
    async def main() -> None:
        stop = asyncio.Event()
        tasks = [asyncio.create_task(_page(port, stop, counts, closes)) for _ in range(n)]
        await asyncio.sleep(seconds)
        stop.set()
        await asyncio.gather(*tasks, return_exceptions=True)

    thread = threading.Thread(target=asyncio.run, args=(main(),), daemon=True)
    thread.start()
    return thread


def timed(port: int, path: str, body: dict | None = None) -> float:
    started = time.perf_counter()
    call(port, path, body, timeout=60)
    return time.perf_counter() - started


def quantiles_ms(values: list[float]) -> dict:
    a = np.asarray(values) * 1e3
    return {"n": len(values), "p50_ms": round(float(np.median(a)), 1),
            "p95_ms": round(float(np.percentile(a, 95)), 1), "max_ms": round(float(a.max()), 1)}


def targets(report: dict) -> dict:
    """/api/health p95 under its bound, counted only if every page the cap admits was really open."""
    p95, open_pages = report["health"]["p95_ms"], report["server_clients"]["open"]
    admitted = min(report["pages"], report["cap"])  # measured while they all still watch
    return {"health_p95_ms": check(p95, HEALTH_P95_BOUND_MS, p95 < HEALTH_P95_BOUND_MS),
            "pages_open": check(open_pages, admitted, open_pages == admitted)}


def measure(args: argparse.Namespace, run_dir: Path) -> dict:
    port = free_port()
    env = {**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl"), "HF_HUB_OFFLINE": "1"}
    with open(run_dir / "serve.log", "w") as log:
        server = subprocess.Popen(serve_command(port, run_dir, args.cap, args.extra), cwd=ROOT, env=env,
                                  stdout=subprocess.DEVNULL, stderr=log)
    try:
        wait_ready(port, server)
        counts, closes = [], []
        watching = pages(port, args.pages, args.seconds + 15, counts, closes)
        time.sleep(5)  # every page connected and pushed to
        health, say, end = [], [], time.monotonic() + args.seconds
        next_say = time.monotonic()
        start_counts = list(counts)
        while time.monotonic() < end:
            health.append(timed(port, "/api/health"))
            if time.monotonic() >= next_say:
                say.append(timed(port, "/api/say", {"text": "Welcome! The dock is over there."}))
                next_say += 2.0
            time.sleep(0.05)
        start_counts += [0] * (len(counts) - len(start_counts))
        rates = (np.asarray(counts) - np.asarray(start_counts)) / args.seconds
        status = call(port, "/api/status")
        watching.join(timeout=30)
    finally:
        server.send_signal(signal.SIGTERM)
        server.wait(timeout=120)
    report = {"pages": args.pages, "cap": args.cap, "seconds": args.seconds, "exit_status": server.returncode,
              "health": quantiles_ms(health), "say": quantiles_ms(say),
              "messages_per_page_per_s": {"median": round(float(np.median(rates)), 2),
                                          "min": round(float(rates.min()), 2)},
              "server_clients": status["clients"], "refused_close_reasons": sorted(set(closes))[:3]}
    report["targets"] = targets(report)
    report["pass"] = all(target["pass"] for target in report["targets"].values())
    return report


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--pages", type=int, default=200)
    parser.add_argument("--cap", type=int, default=250, help="serve.max_clients")
    parser.add_argument("--seconds", type=float, default=30.0)
    parser.add_argument("--extra", nargs="*", default=[], help="more overrides for the serve command")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="emopose-clients-") as folder:
        print(json.dumps(measure(args, Path(folder)), indent=2))


if __name__ == "__main__":
    main()
