"""The G1 voice path without DDS: the chunk schedule on virtual time, the resampling, the sender's
ordering of stops and chunks, the chest light's coalescing, and player=g1's config checks."""

from __future__ import annotations

import logging
import threading
import time
import wave

import numpy as np
import pytest

from emopose.backends.g1.chest_light import COLOURS, ChestLight
from emopose.backends.g1.speaker import G1Player
from emopose.backends.g1.voice import PCM_BYTES_PER_SECOND, chunk_schedule, robot_pcm
from emopose.backends.g1.voice_sender import Chunk, VoiceSender
from emopose.clock import FakeClock


def write_wav(path, samples: np.ndarray, rate: int, channels: int = 1):
    with wave.open(str(path), "wb") as out:
        out.setnchannels(channels)
        out.setsampwidth(2)
        out.setframerate(rate)
        out.writeframes(samples.astype("<i2").tobytes())
    return path


def test_every_chunk_is_sent_ahead_of_its_play_time_by_a_bounded_margin():
    launch, latency, lead = 10.0, 0.25, 0.3
    total = 3 * PCM_BYTES_PER_SECOND + 1000  # 3 s and a short last chunk
    chunks = chunk_schedule(total, 3200, launch, launch + latency, lead)
    assert [c[0] for c in chunks] == list(range(0, total, 3200)) and chunks[-1][1] == total
    margins = [play - send for _, _, send, play in chunks]
    assert all(send >= launch for _, _, send, _ in chunks)
    assert min(margins) == pytest.approx(latency) and max(margins) == pytest.approx(lead)
    assert all(latency - 1e-9 <= m <= lead + 1e-9 for m in margins)
    # after the first few (sent at launch), one chunk leaves every 0.1 s, exactly lead_s early
    assert np.diff([send for _, _, send, _ in chunks[5:]]) == pytest.approx(0.1)


def test_robot_pcm_resamples_and_downmixes_any_16_bit_wav(tmp_path):
    rate = 22050
    tone = (8000 * np.sin(2 * np.pi * 440 * np.arange(rate) / rate)).astype(np.int16)
    mono = robot_pcm(write_wav(tmp_path / "mono.wav", tone, rate))
    expected = np.interp(np.arange(16000) * (rate / 16000), np.arange(rate), tone.astype(np.float32))
    assert np.array_equal(np.frombuffer(mono, "<i2"), expected.astype("<i2"))
    stereo = np.stack([tone, tone // 2], axis=1).reshape(-1)
    downmixed = robot_pcm(write_wav(tmp_path / "stereo.wav", stereo, rate, channels=2))
    averaged = ((tone.astype(np.int32) + tone // 2) // 2).astype(np.float32)
    resampled = np.interp(np.arange(16000) * (rate / 16000), np.arange(rate), averaged)
    assert np.array_equal(np.frombuffer(downmixed, "<i2"), resampled.astype("<i2"))


class RecordingVoice:
    """Stands in for VoiceClient: records calls in order; `fail_on` makes chunk calls raise."""

    def __init__(self, fail_on: int | None = None) -> None:
        self.calls, self.fail_on, self.done = [], fail_on, threading.Event()

    def play_chunk(self, app, stream_id, pcm):
        self.calls.append(("chunk", stream_id, len(pcm)))
        if len(self.calls) == self.fail_on:
            raise TimeoutError("no response")

    def stop_play(self, app):
        self.calls.append(("stop", app))
        self.done.set()

    def set_light(self, rgb):
        self.calls.append(("light", rgb))


def wait_for(predicate, timeout_s=5.0):
    deadline = time.monotonic() + timeout_s
    while not predicate() and time.monotonic() < deadline:
        time.sleep(0.005)
    return predicate()


def test_a_stop_reaches_the_robot_before_the_next_replys_chunks():
    voice, failures = RecordingVoice(), []
    sender = VoiceSender(voice, "emopose", failures.append)
    clock = FakeClock(0.0)  # chunks due at t <= 0 go at once; later ones wait for virtual time
    sender.queue([Chunk("a", b"\0\0", 0.0, 0.3), Chunk("a", b"\0\0", 5.0, 5.3)], clock)
    assert wait_for(lambda: len(voice.calls) == 1)
    sender.stop()  # the second chunk of "a" is dropped, the stop is sent ...
    sender.queue([Chunk("b", b"\0\0", 0.0, 0.3)], clock)  # ... before the next reply's first chunk
    assert wait_for(lambda: len(voice.calls) == 3)
    sender.close()
    assert voice.calls == [("chunk", "a", 2), ("stop", "emopose"), ("chunk", "b", 2)]
    assert (sender.chunks_sent, sender.stops_sent, failures) == (2, 1, [])


def test_a_failed_chunk_drops_the_rest_of_its_stream_and_reports_once(caplog):
    caplog.set_level(logging.INFO)
    voice, failures = RecordingVoice(fail_on=1), []
    sender = VoiceSender(voice, "emopose", failures.append)
    sender.queue([Chunk("a", b"\0\0", 0.0, 0.1), Chunk("a", b"\0\0", 0.0, 0.2)], FakeClock())
    assert wait_for(lambda: failures)
    assert wait_for(lambda: sender.idle)
    sender.close()
    assert voice.calls == [("chunk", "a", 2)] and sender.failures == 1
    assert "its 1 later chunk(s) are not sent" in caplog.text
    assert not [r for r in caplog.records if r.levelno >= logging.WARNING]  # the player warns, once


def test_the_chest_light_shows_the_latest_state_of_a_burst():
    voice = RecordingVoice()
    light = ChestLight(voice, colours={"thinking": (1, 2, 3)}, min_interval_s=0.05)
    light.show("listening")
    assert wait_for(lambda: light.state == "listening")
    light._last_sent_at = float("inf")  # hold the worker: the next states arrive "within 200 ms"
    for state in ("thinking", "speaking", "fault"):
        light.show(state)
    light._last_sent_at = -float("inf")
    assert wait_for(light.settled) and wait_for(lambda: light.state == "fault")
    light.close()
    assert voice.calls == [("light", COLOURS["listening"]), ("light", COLOURS["fault"]),
                           ("light", COLOURS["off"])]
    with pytest.raises(ValueError, match="unknown state 'dancing'"):
        light.show("dancing")
    with pytest.raises(ValueError, match="three integers 0-255"):
        ChestLight(voice, colours={"fault": (300, 0, 0)})


@pytest.mark.parametrize("setting, message", [
    ({"fallback": "browser"}, "player.fallback"), ({"chunk_s": 5.0}, "player.chunk_s"),
    ({"volume": 101}, "player.volume"), ({"app_name": ""}, "player.app_name"),
    ({"latency_s": -0.1}, "player.latency_s")])
def test_bad_settings_are_refused_with_the_key(setting, message):
    with pytest.raises(ValueError, match=message):
        G1Player(**setting)


def test_virtual_time_uses_the_fallbacks_null_sink_without_touching_dds(tmp_path):
    clip_path = write_wav(tmp_path / "a.wav", np.zeros(1600, np.int16), 16000)
    from emopose.speech.clip import SpeechClip

    player, clock = G1Player(), FakeClock(3.0)
    clip = SpeechClip("hi", 0.1, audio_path=clip_path)
    assert player.expected_latency_s(clip, clock) == 0.0
    assert player.play(clip, clock) == 3.0 and player.last_sink == "none"
    assert player._link is None  # the robot was never contacted
