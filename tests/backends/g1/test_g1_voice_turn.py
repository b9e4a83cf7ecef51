"""player=g1 against the fake robot (#33): the robot dies mid-stream in a turn; the heard-onset model.

The documented outcome of a drop mid-stream (README, "The G1's voice"; emopose/backends/g1/speaker.py):
one warning, the next reply plays through player.fallback, nothing raises into the turn and the turn
finishes. Asserted on counters, logs and the turn's own record, never on wall-clock bounds.
"""

from __future__ import annotations

import logging
import threading
import time

import pytest

from emopose.bench.suites import load_sequence
from emopose.build import build_run
from emopose.config import project_path
from emopose.jobs.sync_eval import SyncEvalJob
from emopose.testing.fake_voice import heard_at
from tests.conftest import synthetic_library

FIXTURE_SUITE = project_path("experiments/speech/sync_fixture.jsonl")


def chunk(t: float, stream: str, offset: int, ahead_s: float, size: int = 3200) -> dict:
    return {"kind": "voice_chunk", "t": t, "stream_id": stream, "offset": offset, "bytes": size,
            "ahead_s": ahead_s}


def test_heard_onsets_follow_the_modelled_buffer():
    rows = [chunk(10.0, "a", 0, 0.0), chunk(10.0, "a", 3200, 0.1), chunk(10.25, "a", 6400, -0.05),
            {"kind": "voice_stop", "t": 10.3, "stream_id": "a"}, chunk(11.0, "b", 0, 0.0)]
    assert heard_at(rows, "a", 0.05) == pytest.approx(10.05)       # first chunk sounds on arrival
    assert heard_at(rows, "a", 0.15) == pytest.approx(10.15)       # queued behind the first
    assert heard_at(rows, "a", 0.21) == pytest.approx(10.26)       # ran dry: sounds on its late arrival
    assert heard_at(rows, "a", 0.29) is None                       # the stop cut it before it sounded
    assert heard_at(rows, "a", 0.35) is None and heard_at(rows, "c", 0.0) is None  # never sent
    assert heard_at(rows, "b", 0.0) == pytest.approx(11.0)


@pytest.mark.slow
def test_the_robot_dying_mid_stream_warns_once_falls_back_and_the_turn_finishes(
        fake_robot, domain_id, tmp_path, compose, caplog):
    robot = fake_robot()
    cfg = compose("+experiment=sync_eval", "player=g1", f"player.domain_id={domain_id}",
                  "player.fallback=none", "player.timeout_s=0.5", "player.latency_s=0.0",
                  "player.light=false", "run.clock=monotonic",
                  f"tts.audio_dir={tmp_path / 'tts'}", *synthetic_library(tmp_path / "library"))
    items = load_sequence(FIXTURE_SUITE, anchors_in_text=False)[:2]
    killed = threading.Event()

    def kill_mid_stream() -> None:  # six chunks (0.6 s of audio) in, the robot vanishes
        deadline = time.monotonic() + 30.0
        while len(robot.entries("voice_chunk")) < 6 and time.monotonic() < deadline:
            time.sleep(0.01)
        robot.kill()
        killed.set()

    with build_run(cfg, tmp_path / "run") as run, caplog.at_level(logging.WARNING):
        run.session.open()
        runner = run.runner.with_pipeline(SyncEvalJob._pipeline(run.resources.pipeline, "timeline"))
        player = run.resources.player
        caplog.clear()  # from here on: what the fault logs
        killer = threading.Thread(target=kill_mid_stream, daemon=True)
        killer.start()
        first = runner.run_plan(items[0].plan(), utterance=items[0].text)
        killer.join(timeout=30.0)
        assert killed.is_set() and player.last_sink == "g1"
        deadline = time.monotonic() + 10.0
        while player.sender.failures == 0 and time.monotonic() < deadline:
            time.sleep(0.01)  # the chunk after the kill is waiting for its answer (timeout_s)
        second = runner.run_plan(items[1].plan(), utterance=items[1].text)
    assert first.dispatched.completed and second.dispatched.completed  # both turns finished
    assert player.sender.failures == 1 and player.last_sink == "none"  # the next reply fell back
    total_bytes = player.clips[0][1]
    assert len(player.clips) == 1 and player.sender.chunks_sent < total_bytes / player.chunk_bytes  # cut
    warnings = [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]
    assert all("RpcTimeoutError" in w for w in warnings)  # the one fault, nothing else went wrong
    fallback_notices = [w for w in warnings if "player.fallback=none" in w]
    assert len(fallback_notices) == 1, warnings  # the documented warning, once (the sender adds its own)
