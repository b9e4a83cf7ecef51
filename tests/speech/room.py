"""The robot's voice as its own microphone hears it, for tests and benchmarks/barge_in.py: not a scaled copy
(which an adaptive canceller removes perfectly) but a loudspeaker that compresses its peaks, a delay, a
short room response (direct path and exponentially decaying reflections) and the microphone's noise."""

from __future__ import annotations

import numpy as np

from emopose.speech.audio_in import SAMPLE_RATE


def room_response(gain_db: float, delay_s: float, decay_ms: float, seed: int) -> np.ndarray:
    """Direct path at delay_s, then 100 ms of reflections decaying with time constant decay_ms; the whole
    response's energy is gain_db (the echo return loss at the microphone)."""
    rng = np.random.default_rng(seed)
    delay, tail = round(delay_s * SAMPLE_RATE), round(0.1 * SAMPLE_RATE)
    reflections = rng.normal(0.0, 0.3, tail) * np.exp(-np.arange(tail) / (decay_ms / 1000 * SAMPLE_RATE))
    response = np.concatenate([np.zeros(delay), [1.0], reflections])
    return response * 10 ** (gain_db / 20) / np.sqrt(np.sum(response ** 2))


def room_echo(pcm: bytes, gain_db: float = -12.0, delay_s: float = 0.03, decay_ms: float = 25.0,
              noise_db: float = -65.0, seed: int = 0) -> np.ndarray:
    """Float samples at the int16 scale (mix, then clip), as long as the playback plus its echo tail."""
    played = np.frombuffer(pcm, dtype="<i2").astype(np.float64) / 32768.0
    speaker = np.tanh(1.5 * played) / 1.5  # a small loudspeaker compresses its loudest peaks
    echo = np.convolve(speaker, room_response(gain_db, delay_s, decay_ms, seed))
    noise = np.random.default_rng(seed + 1).normal(0.0, 10 ** (noise_db / 20), len(echo))
    return (echo + noise) * 32768.0
