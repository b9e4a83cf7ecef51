"""Player.play(follow=True): a streamed reply's next clip starts where the playing one ends."""

from __future__ import annotations

import sys
import threading
import time
from pathlib import Path

from emopose.clock import FakeClock
from emopose.speech.clip import SpeechClip
from emopose.speech.player import Player

DEVICE = [sys.executable, "-c", "import sys; open(sys.argv[1], 'a').write('played')"]  # marks its file


class SteppedClock:
    """A real-time clock to the player (devices are used) that moves only when the test says so."""

    realtime = True

    def __init__(self) -> None:
        self.t, self._moved = 0.0, threading.Condition()

    def now(self) -> float:
        return self.t

    def sleep_until(self, deadline: float) -> None:
        with self._moved:
            self._moved.wait_for(lambda: self.t >= deadline, timeout=10)

    def set(self, t: float) -> None:
        with self._moved:
            self.t = t
            self._moved.notify_all()


def _settled_followers() -> None:
    for thread in threading.enumerate():
        if thread.name == "emopose-audio-next":
            thread.join(10)


def _played(path: Path) -> bool:
    for _ in range(500):  # the device is a child process: give it time to write
        if path.exists():
            return True
        time.sleep(0.01)
    return False


def test_the_null_sink_chains_clips_and_plays_at_once_after_a_gap():
    clock, player = FakeClock(1.0), Player(sink="none")
    assert player.play(SpeechClip("a", duration_s=2.0), clock) == 1.0
    assert player.play(SpeechClip("b", duration_s=1.5), clock, follow=True) == 3.0
    assert player.ends_at == 4.5
    clock.advance(10.0)
    assert player.play(SpeechClip("c", duration_s=1.0), clock, follow=True) == 11.0  # nothing playing: now
    assert player.play(SpeechClip("d", duration_s=1.0), clock) == 11.0  # a new reply cuts the old one


def test_a_device_launches_the_next_clip_one_latency_before_the_last_one_ends(tmp_path):
    clock, player = SteppedClock(), Player(sink="auto", latency_s=0.25, command=DEVICE)
    player.play(SpeechClip("a", duration_s=2.0, audio_path=tmp_path / "a"), clock)
    start = player.play(SpeechClip("b", duration_s=1.0, audio_path=tmp_path / "b"), clock, follow=True)
    assert start == 2.25 and player.ends_at == 3.25  # heard when a ends: launched at 2.0
    clock.set(1.9)  # the follower still waits for 2.0
    assert _played(tmp_path / "a") and not (tmp_path / "b").exists()
    clock.set(2.0)
    assert _played(tmp_path / "b")


def test_stop_cancels_a_clip_waiting_to_follow(tmp_path):
    clock, player = SteppedClock(), Player(sink="auto", latency_s=0.0, command=DEVICE)
    player.play(SpeechClip("a", duration_s=2.0, audio_path=tmp_path / "a"), clock)
    player.play(SpeechClip("b", duration_s=1.0, audio_path=tmp_path / "b"), clock, follow=True)
    player.stop()
    clock.set(5.0)
    _settled_followers()
    assert not (tmp_path / "b").exists() and not player.playing(clock)
