"""Speech player start-up in wall time: how long Player.play() takes to return (target < 50 ms).

play() must never block the turn: gestures are released against the start it returns. Two sinks:
  null     the timed null sink with a 30 s clip (player=none, or no audio device)
  device   a device process that plays for 5 s (a Python child standing in for aplay/paplay);
           play() launches it and returns without waiting
For each, --repeats calls on the MonotonicClock; reports p50/p95/max of the return time in ms and
how far the returned start is from the clock at return (launch time + latency for the device).
tests/speech/test_player.py checks the same behaviour on a clock that stands still.
Run: python benchmarks/player_start.py [--repeats 50]  -> JSON on stdout.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout without installing

from emopose.clock import MonotonicClock
from emopose.speech.clip import SpeechClip
from emopose.speech.player import Player

TARGET_MS = 50.0
DEVICE = [sys.executable, "-c", "import time; time.sleep(5)"]


def measure(player: Player, clip: SpeechClip, repeats: int) -> dict:
    clock, returns_ms, offsets_ms = MonotonicClock(), [], []
    for _ in range(repeats):
        before = time.perf_counter()
        start = player.play(clip, clock)
        after = time.perf_counter()
        returns_ms.append((after - before) * 1e3)
        offsets_ms.append((start - after) * 1e3)
        player.stop()
    ms = np.asarray(returns_ms)
    return {"sink": player.last_sink, "return_ms": {"p50": round(float(np.median(ms)), 3),
                                                    "p95": round(float(np.percentile(ms, 95)), 3),
                                                    "max": round(float(ms.max()), 3)},
            "start_minus_return_ms_median": round(float(np.median(offsets_ms)), 3),
            "within_target": bool(ms.max() < TARGET_MS)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=50)
    args = parser.parse_args()
    unread = Path("/nonexistent/clip.wav")  # the stand-in device ignores its file; play() wants a path
    report = {
        "target_ms": TARGET_MS,
        "null": measure(Player(sink="none"), SpeechClip("x", duration_s=30.0), args.repeats),
        "device": measure(Player(sink="auto", latency_s=0.08, command=DEVICE),
                          SpeechClip("x", duration_s=1.0, audio_path=unread), args.repeats),
    }
    print(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
