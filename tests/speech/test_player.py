"""Player: the timed null sink, non-blocking device start, and fallback from a failed device."""

from __future__ import annotations

import logging
import sys
import time

import pytest

from emopose.clock import FakeClock
from emopose.speech.clip import SpeechClip
from emopose.speech.player import Player


class StillClock:
    """A real-time clock to the player (not a FakeClock, so devices are used) that stands still, so a start
    compares exactly and any wait on the clock shows up in `sleeps`. Wall-clock figures:
    benchmarks/player_start.py."""

    realtime = True

    def __init__(self, t: float) -> None:
        self.t, self.sleeps = t, 0

    def now(self) -> float:
        return self.t

    def sleep_until(self, deadline: float) -> None:
        self.sleeps += 1


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
    clock = StillClock(7.0)
    player = Player(sink="none")
    assert player.play(SpeechClip("x", duration_s=30.0), clock) == 7.0 and clock.sleeps == 0
    assert player.playing(clock) and player.ends_at == 37.0  # the null sink "plays" on, untimed by play()


def test_device_start_returns_launch_time_plus_latency_and_stop_is_quiet(clip, caplog, tmp_path):
    clock, played = StillClock(3.0), tmp_path / "played"
    device = f"import pathlib, time; time.sleep(5); pathlib.Path({str(played)!r}).touch()"
    player = Player(sink="auto", latency_s=0.1, command=[sys.executable, "-c", device])
    with caplog.at_level(logging.WARNING):
        assert player.play(clip, clock) == 3.1 and clock.sleeps == 0
        assert not played.exists()  # play() returned while the device was still playing
        player.stop()
        time.sleep(0.3)
    assert player.last_sink.startswith("python")
    assert "exited" not in caplog.text


def test_missing_device_falls_back_to_the_null_sink(clip, caplog):
    clock = StillClock(2.0)
    player = Player(sink="auto", latency_s=0.1, command=["/nonexistent/audio-player"])
    with caplog.at_level(logging.WARNING, logger="emopose.speech.player"):
        start = player.play(clip, clock)
    assert start == 2.0 and player.last_sink == "none"  # the null sink starts now: no device latency
    assert "null sink" in caplog.text


def test_device_that_exits_with_an_error_is_dropped_for_later_replies(clip, caplog):
    clock = StillClock(0.0)
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
