"""Early transcription: a pause in the visitor's speech starts transcribing it; at the VAD end the result
is used only for the very same samples, else the utterance is transcribed then (counters, no clocks)."""

from __future__ import annotations

import threading
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from emopose.speech.audio_in import SAMPLE_RATE
from emopose.speech.early_asr import EarlyTranscripts
from emopose.speech.vad import CHUNK_S
from emopose.speech.wav import write_wav


class CountingRecognizer:
    """Transcribes a WAV as the number of its samples; remembers which files it was asked for."""

    def __init__(self, gate: threading.Event | None = None) -> None:
        self.heard: list[str] = []
        self.gate = gate

    def utterance(self, audio) -> str:
        if self.gate is not None:
            self.gate.wait(10)
        self.heard.append(Path(audio).name)
        return f"{Path(audio).stat().st_size} bytes"


@dataclass
class Pause:
    """What consider() reads of the VAD: speaking, and how long the visitor has paused."""
    speaking: bool = True
    pause_s: float = 0.0


@dataclass
class Pending:
    pcm: bytes = b""

    def pending(self) -> bytes:
        return self.pcm


def speech(seconds: float, seed: int) -> bytes:
    return (np.random.default_rng(seed).normal(0, 3000, int(seconds * SAMPLE_RATE))).astype("<i2").tobytes()


def ended(tmp_path: Path, pcm: bytes, name: str = "utterance.wav") -> Path:
    """The WAV the VAD writes at the end of the visitor's turn."""
    return write_wav(tmp_path / name, pcm, SAMPLE_RATE)


@pytest.fixture
def early(tmp_path):
    made = EarlyTranscripts(CountingRecognizer(), tmp_path / "early", after_ms=96)
    yield made
    made.close()


def test_a_pause_that_ends_the_turn_gives_its_transcript_without_a_second_pass(early, tmp_path):
    vad, utterances = Pause(pause_s=0.096), Pending(speech(1.5, 0))
    early.consider(vad, utterances)
    early.consider(vad, utterances)  # the same samples again: one guess
    text = early.transcript(ended(tmp_path, utterances.pcm))
    assert early.started == 1 and early.used == 1
    assert early.recognizer.heard == ["early-0001.wav"] and text.endswith("bytes")
    assert not list((tmp_path / "early").glob("*.wav"))  # a guess's audio lives only while transcribed


def test_speech_that_goes_on_is_transcribed_at_its_end(early, tmp_path):
    vad, utterances = Pause(pause_s=0.1), Pending(speech(1.0, 1))
    early.consider(vad, utterances)
    utterances.pcm += speech(0.8, 2)  # the visitor spoke on, then the VAD ended the turn
    early.transcript(ended(tmp_path, utterances.pcm))
    assert early.used == 0 and early.recognizer.heard[-1] == "utterance.wav"


@pytest.mark.parametrize("vad", [Pause(pause_s=0.05), Pause(pause_s=0.096 + 2 * CHUNK_S),
                                 Pause(speaking=False, pause_s=0.1)])
def test_only_a_fresh_pause_inside_speech_starts_a_guess(early, vad):
    early.consider(vad, Pending(speech(0.5, 3)))
    assert early.started == 0


def test_a_queued_guess_for_speech_that_went_on_is_dropped(tmp_path):
    gate = threading.Event()
    early = EarlyTranscripts(CountingRecognizer(gate), tmp_path / "early", after_ms=96)
    try:
        vad, utterances = Pause(pause_s=0.1), Pending(speech(0.6, 4))
        early.consider(vad, utterances)            # runs (held at the gate)
        utterances.pcm += speech(0.4, 5)
        early.consider(vad, utterances)            # queued behind it
        utterances.pcm += speech(0.4, 6)
        early.consider(vad, utterances)            # the queued one is cancelled for this one
        gate.set()
        early.transcript(ended(tmp_path, utterances.pcm))
    finally:
        early.close()
    assert early.started == 3 and early.used == 1
    assert early.recognizer.heard == ["early-0001.wav", "early-0003.wav"]  # the second never ran


def test_a_negative_setting_is_refused(tmp_path):
    with pytest.raises(ValueError, match="early_transcribe_ms"):
        EarlyTranscripts(CountingRecognizer(), tmp_path, after_ms=-1)
