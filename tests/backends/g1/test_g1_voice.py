"""player=g1 and the chest light against the fake G1's voice service over real DDS.

Asserts content, order and counters (never wall-clock bounds): the audio the robot received is the
synthesized audio resampled, sample for sample; a stop reaches it after the last chunk it was sent
and before the next reply's first; faults warn and fall back without raising.
"""

from __future__ import annotations

import base64
import json
import logging
import math
import time
import wave

import numpy as np
import pytest

from emopose.backends.g1.chest_light import COLOURS, ChestLight
from emopose.backends.g1.speaker import G1Player
from emopose.clock import MonotonicClock
from emopose.speech.clip import SpeechClip
from emopose.speech.espeak import EspeakSynthesizer

CHUNK = 3200  # chunk_s 0.1


@pytest.fixture(scope="module")
def robot(module_fake_robot):
    return module_fake_robot()


@pytest.fixture(scope="module")
def espeak(tmp_path_factory):
    return EspeakSynthesizer(voice="en-us", rate=165, pitch=50, audio_dir=str(tmp_path_factory.mktemp("tts")))


@pytest.fixture
def player(robot, domain_id):
    made = G1Player(domain_id=domain_id, timeout_s=5.0, fallback="none", volume=35, latency_s=0.2)
    yield made
    made.close()


def expected_pcm(path) -> bytes:
    """The clip's samples at 16 kHz, computed here independently of the player."""
    with wave.open(str(path), "rb") as audio:
        rate, samples = audio.getframerate(), np.frombuffer(audio.readframes(-1), "<i2").astype(np.float32)
    positions = np.arange(round(len(samples) * 16000 / rate)) * (rate / 16000)
    return np.interp(positions, np.arange(len(samples)), samples).astype("<i2").tobytes()


def stream(robot, stream_id: str, count: int) -> list[dict]:
    deadline = time.monotonic() + 15.0
    while len(rows := [r for r in robot.entries("voice_chunk") if r["stream_id"] == stream_id]) < count:
        assert time.monotonic() < deadline, f"{len(rows)} of {count} chunks of stream {stream_id} arrived"
        time.sleep(0.02)
    return rows


def test_the_robot_receives_the_synthesized_audio_sample_for_sample(player, robot, espeak):
    clip = espeak.synthesize("Welcome to the lab. The robot arm is over there.")
    clock = MonotonicClock()
    assert player.expected_latency_s(clip, clock) == 0.2  # the link is up: the robot's latency
    start = player.play(clip, clock)
    stream_id, total, launch, sound_start = player.clips[-1]
    assert player.last_sink == "g1" and start == sound_start == pytest.approx(launch + 0.2)
    rows = stream(robot, stream_id, math.ceil(total / CHUNK))
    assert [r["offset"] for r in rows] == list(range(0, total, CHUNK))  # in order, none missing or twice
    received = b"".join(base64.b64decode(r["pcm"]) for r in rows)
    assert received == expected_pcm(clip.audio_path) and len(received) == total
    volume = [json.loads(r["parameter"]) for r in robot.entries("voice") if r["api_id"] == 1006]
    assert volume[-1] == {"volume": 35}


def test_a_following_sentence_continues_the_stream_and_a_new_reply_cuts_it(player, robot, espeak):
    first, second = espeak.synthesize("First sentence."), espeak.synthesize("Second one.")
    clock = MonotonicClock()
    player.play(first, clock)
    player.play(second, clock, follow=True)  # launched when the first ends, on the same stream
    deadline = time.monotonic() + 15.0
    while len(player.clips) < 2:
        assert time.monotonic() < deadline
        time.sleep(0.02)
    (a, a_bytes, _, a_start), (b, b_bytes, _, b_start) = player.clips[-2:]
    assert a == b and b_start == pytest.approx(a_start + first.duration_s, abs=0.05)
    rows = stream(robot, a, math.ceil(a_bytes / CHUNK) + math.ceil(b_bytes / CHUNK))
    assert b"".join(base64.b64decode(r["pcm"]) for r in rows) == (expected_pcm(first.audio_path)
                                                                 + expected_pcm(second.audio_path))
    player.play(first, clock)  # a new reply: stop play, then a new stream
    c = player.clips[-1][0]
    stream(robot, c, 1)
    log = robot.entries()
    stop_at = max(i for i, r in enumerate(log) if r["kind"] == "voice_stop" and r["stream_id"] == a)
    first_c = min(i for i, r in enumerate(log) if r["kind"] == "voice_chunk" and r["stream_id"] == c)
    assert c != a and stop_at < first_c


def test_stop_after_an_interrupt_cuts_the_stream(player, robot, tmp_path):
    path = tmp_path / "long.wav"
    with wave.open(str(path), "wb") as out:
        out.setnchannels(1), out.setsampwidth(2), out.setframerate(16000)
        out.writeframes((np.arange(16000 * 4) % 200 - 100).astype("<i2").tobytes())
    clock = MonotonicClock()
    player.play(SpeechClip("long", 4.0, audio_path=path), clock)
    stream_id, total, _, _ = player.clips[-1]
    stream(robot, stream_id, 4)
    stops_before = player.sender.stops_sent
    interrupted_at = time.monotonic()
    player.stop()
    deadline = time.monotonic() + 10.0
    while not (stops := [r for r in robot.entries("voice_stop") if r["stream_id"] == stream_id]):
        assert time.monotonic() < deadline, "no stop play arrived"
        time.sleep(0.01)
    time.sleep(0.3)  # any chunk still in flight would now be in the log
    log = robot.entries()
    stop_at = next(i for i, r in enumerate(log) if r["kind"] == "voice_stop" and r["stream_id"] == stream_id)
    chunks = [i for i, r in enumerate(log) if r["kind"] == "voice_chunk" and r["stream_id"] == stream_id]
    assert max(chunks) < stop_at and len(chunks) < total / CHUNK  # cut, and nothing after the stop
    assert player.sender.stops_sent == stops_before + 1 and not player.playing(clock)
    print(f"stop arrived {1000 * (stops[0]['t'] - interrupted_at):.1f} ms after stop(); "
          f"it cut {stops[0]['cut_s']:.2f} s of queued audio")


def test_the_chest_light_shows_each_state_and_goes_off(player, robot):
    light = ChestLight(player.voice)
    for state in ("listening", "thinking", "speaking", "fault"):
        light.show(state)
        deadline = time.monotonic() + 5.0
        while light.state != state:
            assert time.monotonic() < deadline, f"{state} was not confirmed"
            time.sleep(0.01)
    light.close()
    shown = [json.loads(r["parameter"]) for r in robot.entries("voice") if r["api_id"] == 1010]
    wanted = [COLOURS[s] for s in ("listening", "thinking", "speaking", "fault", "off")]
    assert [(p["R"], p["G"], p["B"]) for p in shown[-5:]] == wanted


def test_an_unanswered_voice_service_warns_and_falls_back(robot, domain_id, espeak, caplog):
    lonely = G1Player(domain_id=domain_id, service="no_such_voice", timeout_s=0.3, fallback="none")
    clip, clock = espeak.synthesize("Hello."), MonotonicClock()
    with caplog.at_level(logging.WARNING, logger="emopose.backends.g1.speaker"):
        start = lonely.play(clip, clock)
    assert lonely.last_sink == "none" and start <= clock.now()
    assert "voice service failed (RpcTimeoutError" in caplog.text and "player.fallback=none" in caplog.text
    assert lonely.expected_latency_s(clip, clock) == 0.0  # no retry before retry_s: no second wait
    lonely.close()


def test_a_refused_chunk_warns_and_the_next_reply_falls_back(module_fake_robot, domain_id, espeak, caplog):
    module_fake_robot("--voice-service", "refusing_voice", "--fail-api", "1003:3204")
    refused = G1Player(domain_id=domain_id, service="refusing_voice", timeout_s=5.0, fallback="none")
    clip, clock = espeak.synthesize("Hello there."), MonotonicClock()
    with caplog.at_level(logging.WARNING):
        assert refused.play(clip, clock) > clock.now() - 1.0 and refused.last_sink == "g1"
        deadline = time.monotonic() + 10.0
        while refused.sender.failures == 0:
            assert time.monotonic() < deadline
            time.sleep(0.01)
        refused.play(clip, clock)
    assert "failed with status code 3204" in caplog.text and refused.last_sink == "none"
    assert refused.sender.chunks_sent == 0 and refused.sender.failures == 1
    refused.close()

