"""Player: the timed null sink, non-blocking device start, and fallback from a failed device."""

from __future__ import annotations

import logging
import sys
import time

import pytest

from emopose.clock import FakeClock, MonotonicClock
from emopose.speech.clip import SpeechClip
from emopose.speech.player import Player


@pytest.fixture
def clip(espeak) -> SpeechClip:
    return espeak.synthesize("The robot arm is over there.")


def test_null_sink_starts_now_and_plays_for_the_clip_duration(clip):
    clock = FakeClock(5.0)
    player = Player(sink="none")
    start = player.play(clip, clock)
    assert start == 5.0 and player.last_sink == "none"
    clock.advance(clip.duration_s - 0.01)
    assert player.playing(clock)
    clock.advance(0.02)
    assert not player.playing(clock)


def test_auto_uses_the_null_sink_on_virtual_time(clip):
    clock = FakeClock(1.0)
    assert Player(sink="auto", command=[sys.executable, "-c", "pass"]).play(clip, clock) == 1.0


def test_play_never_blocks_even_for_a_long_clip():
    clock = MonotonicClock()
    long_clip = SpeechClip("x", duration_s=30.0)
    started = time.perf_counter()
    start = Player(sink="none").play(long_clip, clock)
    assert time.perf_counter() - started < 0.05 and abs(start - clock.now()) < 0.05


def test_device_start_returns_launch_time_plus_latency_and_stop_is_quiet(clip, caplog):
    clock = MonotonicClock()
    player = Player(sink="auto", latency_s=0.1, command=[sys.executable, "-c", "import time; time.sleep(5)"])
    before = clock.now()
    with caplog.at_level(logging.WARNING):
        start = player.play(clip, clock)
        assert before + 0.1 <= start <= clock.now() + 0.1 and clock.now() - before < 0.5  # did not wait
        player.stop()
        time.sleep(0.3)
    assert player.last_sink.startswith("python")
    assert "exited" not in caplog.text


def test_missing_device_falls_back_to_the_null_sink(clip, caplog):
    clock = MonotonicClock()
    player = Player(sink="auto", latency_s=0.1, command=["/nonexistent/audio-player"])
    with caplog.at_level(logging.WARNING, logger="emopose.speech.player"):
        start = player.play(clip, clock)
    assert abs(start - clock.now()) < 0.05 and player.last_sink == "none"
    assert "null sink" in caplog.text


def test_device_that_exits_with_an_error_is_dropped_for_later_replies(clip, caplog):
    clock = MonotonicClock()
    player = Player(sink="auto", command=[sys.executable, "-c", "import sys; sys.exit(3)"])
    with caplog.at_level(logging.WARNING, logger="emopose.speech.player"):
        player.play(clip, clock)
        deadline = time.monotonic() + 5
        while "exited" not in caplog.text and time.monotonic() < deadline:
            time.sleep(0.02)
    assert "exited with 3" in caplog.text
    player.play(clip, clock)
    assert player.last_sink == "none"


def test_config_is_validated():
    with pytest.raises(ValueError, match="player.sink"):
        Player(sink="speakers")
