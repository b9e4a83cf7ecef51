"""player=g1 (#33) against the fake robot on loopback DDS: first chunk, stop, strokes on the words as heard.

    python benchmarks/g1_voice_timing.py [--trials 30] [--items 20] [--latency-s S] [--domain-id N]

first_chunk: a G1Player plays a new reply --trials times; the delay from the launch (the instant the
    host's own player would start its audio, G1Player.clips' launch) to the fake robot receiving the
    stream's first chunk (its log's arrival time; both clocks are CLOCK_MONOTONIC). Target <= 50 ms.
stop: in each of those trials, once the first chunk has arrived, player.stop() (what an interrupt or a
    barge-in calls) to the fake robot receiving stop play for that stream. Target <= 100 ms.
strokes: --items sequence-suite items run as turns (annotated plans, timeline schedule, dry_run on wall
    time, recorded) with player=g1. The strokes are read back from session.mcap
    (emopose.sync.recording.read_stroke_sync) and their trigger words' onsets replaced by the onsets as
    the fake robot's modelled buffer sounds them (emopose.testing.fake_voice.heard_at), then summarised
    as sync_eval does, with its targets. The fake sounds a new stream on arrival, so its launch-to-sound
    latency is the first chunk's delay: player.latency_s is set to that median (the calibration the
    README describes) unless --latency-s is given.
Prints one JSON object.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import random
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from hydra import compose, initialize_config_dir

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from g1_publish import start_fake  # noqa: E402  (this folder is on sys.path when run as a script)

from emopose.backends.g1.speaker import G1Player  # noqa: E402
from emopose.build import build_run  # noqa: E402
from emopose.clock import MonotonicClock  # noqa: E402
from emopose.config import CONFIG_DIR  # noqa: E402  (and registers the config's resolvers)
from emopose.jobs.sync_eval import SyncEvalJob  # noqa: E402
from emopose.speech.espeak import EspeakSynthesizer  # noqa: E402
from emopose.sync.recording import read_stroke_sync  # noqa: E402
from emopose.sync.strokes import stroke_summary, unmet_targets  # noqa: E402
from emopose.testing.fake_voice import heard_at  # noqa: E402

FIRST_CHUNK_TARGET_MS = 50.0
STOP_TARGET_MS = 100.0


def log_rows(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text().split("\n")[:-1] if line.strip()]


def first_arrival(log: Path, stream_id: str, kind: str = "voice_chunk", timeout_s: float = 5.0) -> float:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        rows = [r for r in log_rows(log) if r["kind"] == kind and r["stream_id"] == stream_id]
        if rows:
            return rows[0]["t"]
        time.sleep(0.01)
    raise SystemExit(f"no {kind} of stream {stream_id} reached the fake robot")


def delays_summary(delays: list[float], target_ms: float) -> dict:
    ms = np.asarray(delays)
    return {"trials": len(delays), "median_ms": round(float(np.median(ms)), 2),
            "p95_ms": round(float(np.percentile(ms, 95)), 2), "max_ms": round(float(ms.max()), 2),
            "target_ms": target_ms, "met": bool(np.percentile(ms, 95) <= target_ms)}


def first_chunk_and_stop(domain_id: int, log: Path, trials: int, folder: str) -> dict:
    player = G1Player(domain_id=domain_id, fallback="none", timeout_s=2.0, latency_s=0.0)
    clip = EspeakSynthesizer(audio_dir=folder).synthesize("Welcome to the lab, let me show you around.")
    clock, firsts, stops = MonotonicClock(), [], []
    try:
        player.play(clip, clock)  # the link comes up on first use: not counted
        player.stop()
        for _ in range(trials):
            time.sleep(0.2)
            player.play(clip, clock)
            stream_id, _, launch, _ = player.clips[-1]
            firsts.append((first_arrival(log, stream_id) - launch) * 1e3)
            interrupted = time.monotonic()  # mid-stream, as an interrupt or a barge-in
            player.stop()
            stops.append((first_arrival(log, stream_id, "voice_stop") - interrupted) * 1e3)
    finally:
        player.close()
    return {"first_chunk": delays_summary(firsts, FIRST_CHUNK_TARGET_MS),
            "stop": delays_summary(stops, STOP_TARGET_MS)}


def run_turns(domain_id: int, latency_s: float, items: int, folder: Path) -> tuple[Path, list, dict]:
    """Run the items as turns; (session.mcap, [(stream id, speech start)] per turn, the targets)."""
    overrides = ["+experiment=sync_eval", "player=g1", f"player.domain_id={domain_id}",
                 "player.fallback=none", f"player.latency_s={latency_s}", "player.light=false",
                 "run.clock=monotonic", "run.record=true", f"tts.audio_dir={folder / 'tts'}"]
    with initialize_config_dir(config_dir=str(CONFIG_DIR), version_base="1.3"):
        cfg = compose("config", overrides=overrides)
    job = SyncEvalJob(**{k: v for k, v in cfg.job.items() if k != "_target_"})
    turns = []
    with build_run(cfg, folder / "run") as run:
        run.session.open()
        runner = run.runner.with_pipeline(SyncEvalJob._pipeline(run.resources.pipeline, "timeline"))
        for item in job._items()[1][:items]:
            turn = runner.run_plan(item.plan(), utterance=item.text)
            turns.append((run.resources.player.clips[-1][0], turn.dispatched.speech_start))
    return folder / "run" / "session.mcap", turns, dict(job.stroke_targets)


def heard_strokes(recording: Path, turns: list, log: Path) -> tuple[list, list]:
    """The recording's strokes, and the same against the onsets as the fake robot sounded them."""
    rows, heard = read_stroke_sync(recording), []
    log_entries = log_rows(log)
    for row in rows:
        stream_id, speech_start = turns[int(row.item.removeprefix("turn-"))]
        sounded = None if row.onset_s is None else heard_at(log_entries, stream_id, row.onset_s)
        heard.append(dataclasses.replace(row, onset_s=None if sounded is None else sounded - speech_start))
    return rows, heard


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=30)
    parser.add_argument("--items", type=int, default=20)
    parser.add_argument("--latency-s", type=float, default=None, help="default: the measured first chunk")
    parser.add_argument("--domain-id", type=int, default=random.SystemRandom().randint(20, 230))
    args = parser.parse_args()
    folder = Path(tempfile.mkdtemp(prefix="emopose-g1-voice-"))
    log = folder / "fake.jsonl"
    fake = start_fake(args.domain_id, "--log", str(log))
    try:
        report = first_chunk_and_stop(args.domain_id, log, args.trials, str(folder / "tts"))
        latency_s = args.latency_s if args.latency_s is not None else report["first_chunk"]["median_ms"] / 1e3
        recording, turns, targets = run_turns(args.domain_id, latency_s, args.items, folder)
        planned, heard = heard_strokes(recording, turns, log)
    finally:
        fake.terminate()
        fake.wait(timeout=10)
    for name, rows in (("strokes_vs_planned_onsets", planned), ("strokes_vs_heard_onsets", heard)):
        summary = stroke_summary(rows, simulated=False)
        report[name] = {**summary, "unmet_targets": unmet_targets(summary, targets)}
    report.update(latency_s=latency_s, turns=len(turns), targets=targets)
    print(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
