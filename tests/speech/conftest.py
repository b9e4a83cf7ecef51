"""Speech fixtures: a real espeak-ng synthesizer writing into a temporary audio folder; a WAV writer."""

from __future__ import annotations

import wave

import numpy as np
import pytest

from emopose.speech.espeak import EspeakSynthesizer


@pytest.fixture(scope="session")
def espeak(tmp_path_factory) -> EspeakSynthesizer:
    return EspeakSynthesizer(voice="en-us", rate=165, pitch=50, audio_dir=str(tmp_path_factory.mktemp("tts")))


def write_pcm16(path, samples: np.ndarray, rate: int = 16000, channels: int = 1):
    """A 16-bit WAV of `samples` (clipped to the int16 range), interleaved when channels > 1."""
    with wave.open(str(path), "wb") as out:
        out.setnchannels(channels)
        out.setsampwidth(2)
        out.setframerate(rate)
        out.writeframes(np.clip(samples, -32768, 32767).astype("<i2").tobytes())
    return path
