"""Streamed turns (#17 item 6): how soon the robot speaks when the reply streams, against a whole answer.

A local OpenAI-compatible server (tests/planners/fake_openai.py, its own process) writes a four-sentence
reply at --tokens-per-s after --first-token-s (default 30 tokens/s after 300 ms; every request's reply
differs, so no speech cache helps). The whole serve pipeline runs on the real-time clock
(+experiment=serve, planner=annotate with its configured annotator, espeak timings without WAVs,
the null sink player, dry_run backend). Per repeat:
  streamed    planner.stream=true: request -> speech start of the first sentence, next to the time the
              first sentence was complete (the splitter sees its end when the next token arrives),
              with the breakdown: first token, first sentence, annotate, synthesize, schedule
              (without synthesis), sequence, dispatch (the first sentence's bounded pre-roll is in it),
              and the whole answer's time (the last sentence complete)
  unstreamed  the same server answering the same reply whole (planner.stream=false): request -> speech start
Target: p95 of (speech start - first sentence complete) <= 150 ms.
Between repeats the reply is cut off as the web UI's interrupt does.
Run: python benchmarks/streamed_turn.py [--repeats 20] [--annotator local|keyword] [--stream-preroll-s S]
  -> JSON on stdout.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "tests")]

from conftest import compose_config

from emopose.build import build_run
from emopose.planners.baselines.keyword import KeywordPlanner

FAKE_SERVER = ROOT / "tests" / "planners" / "fake_openai.py"
REPLY = ("Hello, visitor {n}, welcome to the lab! The charging dock is over there, by the window. "
         "Please do not touch the robot arm while it is calibrating. I can show you the demo next.")
TARGET_S = 0.150


class TimedSynthesizer:
    """The schedule stage's synthesizer, timed: synthesis is reported apart from the schedule."""

    def __init__(self, inner) -> None:
        self.inner, self.name, self.calls = inner, inner.name, []

    def synthesize(self, text: str):
        started = time.perf_counter()
        clip = self.inner.synthesize(text)
        self.calls.append(time.perf_counter() - started)
        return clip


def stats(values: list[float]) -> dict:
    ms = np.asarray(values) * 1e3
    return {"p50_ms": round(float(np.median(ms)), 1), "p95_ms": round(float(np.percentile(ms, 95)), 1),
            "max_ms": round(float(ms.max()), 1)}


def start_server(first_token_s: float, tokens_per_s: float) -> tuple[subprocess.Popen, str]:
    proc = subprocess.Popen([sys.executable, str(FAKE_SERVER), "--reply", REPLY, "--first-token-s",
                             str(first_token_s), "--tokens-per-s", str(tokens_per_s)],
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    return proc, json.loads(proc.stdout.readline())["url"]


def build(url: str, annotator: str, preroll_s: float | None, run_dir: Path):
    preroll = [] if preroll_s is None else [f"planner.stream_preroll_s={preroll_s}"]
    cfg = compose_config([*preroll, "+experiment=serve", "planner=annotate", "planner.stream=true",
                          "planner.client.model=openai/bench", f"planner.client.api_base={url}",
                          "planner.client.cache=false", "player=none", "tts=espeak", "tts.write_audio=false",
                          f"tts.audio_dir={run_dir / 'tts'}", "backend=dry_run", "run.record=false"])
    run = build_run(cfg, run_dir)
    if annotator == "keyword":
        run.runner.planner.annotator = KeywordPlanner()
    schedule = run.resources.pipeline.get("schedule")
    schedule.synthesizer = timed = TimedSynthesizer(schedule.synthesizer)
    return run, timed


def quiet(run) -> None:
    """Cut the last reply off as the web UI's interrupt does, and wait for the arms to settle."""
    loop, sequencer = run.session.loop, run.resources.sequencer
    sequencer.interrupt([], now=loop.clock.now())
    run.resources.player.stop()
    loop.wait_until(sequencer.settled, 30.0)


def streamed_repeat(run, timed: TimedSynthesizer) -> dict:
    timed.calls.clear()
    started = time.perf_counter()
    reply = run.runner.run_streamed("Hi! Where can I charge my phone?")
    if reply.error or not reply.turns:
        raise RuntimeError(f"the streamed reply failed: {reply.error}")
    first, meta = reply.turns[0], reply.turns[0].planner_output.meta
    synth = timed.calls[0]
    return {"speech_start": first.dispatched.speech_start - started, "first_token": meta["first_token_s"],
            "first_sentence": meta["sentence_s"], "annotate": meta["annotate_s"], "synthesize": synth,
            "parse_resolve_modulate": sum(first.stage_s[s] for s in ("parse", "resolve", "modulate")),
            "schedule": first.stage_s["schedule"] - synth, "sequence": first.stage_s["sequence"],
            "dispatch": first.stage_s["dispatch"], "preroll": first.schedule.preroll_s,
            "whole_answer": reply.turns[-1].planner_output.meta["sentence_s"], "sentences": len(reply.turns)}


def unstreamed_repeat(run) -> float:
    started = time.perf_counter()
    turn = run.runner.run("Hi! Where can I charge my phone?")
    return turn.dispatched.speech_start - started


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=20)
    parser.add_argument("--first-token-s", type=float, default=0.3)
    parser.add_argument("--tokens-per-s", type=float, default=30.0)
    parser.add_argument("--annotator", choices=["local", "keyword"], default="local",
                        help="local: the configured annotator (planner=local); keyword: the keyword rules")
    parser.add_argument("--stream-preroll-s", type=float, default=None, help="default: the configured one")
    args = parser.parse_args()
    proc, url = start_server(args.first_token_s, args.tokens_per_s)
    try:
        with tempfile.TemporaryDirectory() as tmp:
            run, timed = build(url, args.annotator, args.stream_preroll_s, Path(tmp))
            with run.session:
                run.session.open().start()
                streamed_repeat(run, timed)  # warm-up: litellm's import and first connection
                quiet(run)
                rows = []
                for _ in range(args.repeats):
                    rows.append(streamed_repeat(run, timed))
                    quiet(run)
                run.runner.planner.streams = False  # the same planner and server, answering whole
                whole = []
                for _ in range(args.repeats):
                    whole.append(unstreamed_repeat(run))
                    quiet(run)
    finally:
        proc.stdin.close()
        proc.wait(timeout=5)
    margin = [r["speech_start"] - r["first_sentence"] for r in rows]
    keys = [k for k in rows[0] if k != "sentences"]
    report = {
        "server": {"first_token_s": args.first_token_s, "tokens_per_s": args.tokens_per_s},
        "annotator": args.annotator, "stream_preroll_s": run.runner.planner.stream_preroll_s,
        "repeats": args.repeats, "sentences": rows[0]["sentences"],
        "streamed": {k: stats([r[k] for r in rows]) for k in keys},
        "speech_start_minus_first_sentence": stats(margin),
        "unstreamed_speech_start": stats(whole),
        "target_ms": TARGET_S * 1e3,
        "within_target": bool(np.percentile(margin, 95) <= TARGET_S),
    }
    print(json.dumps(report, indent=1))


if __name__ == "__main__":
    main()
