"""Live serve under load: stroke sync and control-loop timing of `serve` driven over its HTTP API.

Starts `python -m emopose +experiment=serve backend=mujoco tts=espeak player=none` on a free port in a
fresh run directory, keeps --busy cores busy with `while True` processes (and --pages WebSocket pages
watching, so frames are rendered), sends --items texts of experiments/sequence/sequence_suite.jsonl
to /api/say one at a time (each waiting until the robot is idle again), stops the server with SIGTERM
and reads its session.mcap and results.json:
  strokes       share within [-200, +100] ms of the trigger onset on the command stream and on the
                simulated joints, median |offset|, dropped share (emopose.sync.strokes.stroke_summary)
  gold anchors  the same executed strokes against the onsets of the suite's annotated anchors (the words
                each gesture belongs to; an anchor without a gesture counts as missed), as sync_eval's
                stroke-vs-gold-anchor: what a listener sees, the planner's triggers included
  loop          missed deadlines / ticks, stalls, lateness (results.json) and the largest gap between
                two recorded commands (/joints/command)
  latency       request -> speech start and request -> first executed stroke, median and p95
  joints        the simulated joints (/joints/sim) against the hard limits and the speed bounds
                (emopose.sync.joint_bounds)
Server and benchmark share the machine's monotonic clock (time.perf_counter), so request times and the
server's clock times compare directly.
Run: python benchmarks/live_serve.py [--items 320] [--busy 1] [--pages 0] [--extra key=value ...]
  -> JSON on stdout (--extra run.rt_priority=0: the loop without its raised priority, for comparison).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import signal
import socket
import subprocess
import sys
import threading
import time
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # run from a checkout without installing

from emopose.joint_limits import JointLimits
from emopose.recording import read_recording
from emopose.sync.joint_bounds import joint_bounds
from emopose.sync.recording import read_gold_anchor_sync, read_stroke_sync
from emopose.sync.strokes import stroke_summary

sys.path.insert(0, str(Path(__file__).resolve().parent))
from run_dirs import measure_and_print  # noqa: E402

SUITE = ROOT / "experiments" / "sequence" / "sequence_suite.jsonl"
LIMITS = ROOT / "library" / "g1" / "limits.yaml"  # the default library set's (serve's default)
BUSY_LOOP = "while True:\n    pass\n"


@contextlib.contextmanager
def busy_cores(n: int) -> Iterator[None]:
    """n other processes, each keeping a core busy, while inside (issue 28's load; serve_soak.py --busy)."""
    busy = [subprocess.Popen([sys.executable, "-c", BUSY_LOOP]) for _ in range(n)]
    try:
        yield
    finally:
        for process in busy:
            process.kill()
            process.wait()


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def call(port: int, path: str, body: dict | None = None, timeout: float = 120.0) -> dict:
    data = None if body is None else json.dumps(body).encode()
    request = urllib.request.Request(f"http://127.0.0.1:{port}{path}", data=data,
                                     headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(request, timeout=timeout) as response:
        return json.loads(response.read())


def wait_ready(port: int, server: subprocess.Popen, timeout_s: float = 300.0) -> None:
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        if server.poll() is not None:
            raise RuntimeError(f"serve exited with {server.returncode} before it answered")
        try:
            call(port, "/api/health", timeout=2)
            return
        except OSError:
            time.sleep(0.5)
    raise TimeoutError("serve did not answer /api/health")


def wait_idle(port: int, speech_end: float, timeout_s: float = 60.0) -> None:
    """Until the turn's speech has ended (server clock) and the sequencer runs and holds nothing: the robot
    finished the turn. The sequencer alone is not enough: between two gestures of a turn it can be empty
    while the speech goes on, and the next text would then interrupt the turn."""
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        status = call(port, "/api/status")
        if status["server_now"] >= speech_end and status["active"] is None and not status["pending"]:
            return
        time.sleep(0.1)


def drive(port: int, texts: list[str]) -> list[dict]:
    """One turn per text; per turn the request time and its published sentence turns, read back from the
    log once the robot is idle (a cue's executed stroke time lands there after the reply returned)."""
    sent, by_id = [], {}  # (request time, id of the reply's last message); turn messages by id
    for text in texts:
        requested = time.perf_counter()
        reply = call(port, "/api/say", {"text": text})  # the reply's last sentence turn
        sent.append((requested, reply["id"]))
        wait_idle(port, (reply.get("speech_start") or 0.0) + reply.get("speech", {}).get("duration_s", 0.0))
        # the server keeps a bounded log: collect each turn (with its executed strokes) while it is there
        by_id |= {m["id"]: m for m in call(port, "/api/turns")["log"] if m["type"] == "turn"}
    turns, previous = [], 0
    for requested, last in sent:  # a streamed reply publishes one turn per sentence: the first speaks first
        sentences = [m for key, m in sorted(by_id.items()) if previous < key <= last]
        if sentences:
            turns.append({"requested": requested, "sentences": sentences})
        previous = last
    return turns


def watch(port: int, stop: threading.Event) -> None:
    """A page watching: the WebSocket that receives state and frames (so the server renders them)."""
    from websockets.sync.client import connect

    with connect(f"ws://127.0.0.1:{port}/ws", max_size=None) as websocket:
        while not stop.is_set():
            try:
                websocket.recv(timeout=0.5)
            except TimeoutError:
                continue


def percentiles(values: list[float]) -> dict | None:
    if not values:
        return None
    array = np.asarray(values) * 1e3
    return {"n": len(values), "median_ms": float(np.median(array)), "p95_ms": float(np.percentile(array, 95))}


def latencies(turns: list[dict]) -> dict:
    to_speech, to_stroke = [], []
    for row in turns:
        starts = [m["speech_start"] for m in row["sentences"] if m.get("speech_start") is not None]
        if starts:
            to_speech.append(min(starts) - row["requested"])
        executed = [m["speech_start"] + c["stroke_executed_s"] for m in row["sentences"]
                    for c in m.get("cues", []) if c.get("stroke_executed_s") is not None]
        if executed:
            to_stroke.append(min(executed) - row["requested"])
    return {"request_to_speech": percentiles(to_speech), "request_to_first_stroke": percentiles(to_stroke)}


def command_gaps(topics: dict) -> dict:
    times = np.array([m["t"] for _, m in topics.get("/joints/command", [])])
    gaps = np.diff(times) * 1e3 if times.size > 1 else np.zeros(1)
    gaps = np.round(gaps, 3)  # stream times are multiples of 20 ms up to float error
    return {"max_command_gap_ms": float(gaps.max()), "gaps_over_40ms": int(np.sum(gaps > 40)),
            "gaps_over_60ms": int(np.sum(gaps > 60))}


def simulated_joint_bounds(topics: dict) -> dict:
    rows = topics.get("/joints/sim", [])
    times = np.array([m["t"] for _, m in rows])
    q = np.array([m["q"] for _, m in rows])
    return joint_bounds(times, q, JointLimits.from_file(LIMITS))


def serve_command(port: int, run_dir: Path, extra: list[str]) -> list[str]:
    return [sys.executable, "-m", "emopose", "+experiment=serve", "backend=mujoco", "tts=espeak",
            "player=none", f"serve.port={port}", f"hydra.run.dir={run_dir}", *extra]


def measure(args: argparse.Namespace, run_dir: Path) -> dict:
    items = [json.loads(line) for line in SUITE.read_text().splitlines() if line.strip()][: args.items]
    port = free_port()
    env = {**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl"), "HF_HUB_OFFLINE": "1"}
    stop_pages = threading.Event()
    with busy_cores(args.busy):
        with open(run_dir / "serve.log", "w") as serve_log:
            server = subprocess.Popen(serve_command(port, run_dir, args.extra), cwd=ROOT, env=env,
                                      stdout=subprocess.DEVNULL, stderr=serve_log)
        try:
            wait_ready(port, server)
            for _ in range(args.pages):
                threading.Thread(target=watch, args=(port, stop_pages), daemon=True).start()
            started = time.monotonic()
            turns = drive(port, [item["text"] for item in items])
            driven_s = time.monotonic() - started
        finally:
            stop_pages.set()
            server.send_signal(signal.SIGTERM)
            server.wait(timeout=120)
    topics = read_recording(run_dir / "session.mcap")  # once: a long session's file takes minutes
    rows = read_stroke_sync(topics)
    gold, unspoken = read_gold_anchor_sync(topics, [(item["text"], item["anchors"]) for item in items])
    results = json.loads((run_dir / "results.json").read_text())
    loop = results["loop"]
    return {"command": " ".join(serve_command(port, run_dir, args.extra)[1:]), "items": len(items),
            "busy": args.busy, "pages": args.pages, "driven_s": round(driven_s, 1),
            "strokes_commands": stroke_summary(rows),
            "strokes_simulated": stroke_summary(rows, simulated=True),
            "strokes_gold_anchor_commands": stroke_summary(gold) | {"anchors_not_spoken": unspoken},
            "strokes_gold_anchor_simulated": stroke_summary(gold, simulated=True),
            "loop": {**loop, **command_gaps(topics)},
            "simulated_joints": simulated_joint_bounds(topics), **latencies(turns)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--items", type=int, default=320)
    parser.add_argument("--busy", type=int, default=1, help="processes keeping a core busy the whole time")
    parser.add_argument("--pages", type=int, default=0, help="WebSocket pages watching (frames rendered)")
    parser.add_argument("--extra", nargs="*", default=[], help="more overrides for the serve command")
    parser.add_argument("--run-dir", type=Path, default=None, help="keep the run here (default: a temp dir)")
    measure_and_print(measure, parser.parse_args(), "emopose-live-")


if __name__ == "__main__":
    main()
