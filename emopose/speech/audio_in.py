"""Audio input for recognition and voice activity: any file -> 16 kHz mono float32, with its checks.

Decoding goes through PyAV (faster-whisper's decode_audio), so WAV at any rate or channel count, and
the browser's webm/ogg, all arrive as 16 kHz mono (stereo is averaged, 8 kHz is resampled: documented,
not refused). What is refused, with one line naming the file: a missing file, an unknown suffix, a file
that does not decode, and audio longer than the configured bound. Clipping is reported, not refused.
"""

from __future__ import annotations

import wave
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from emopose.speech.asr import ASRError, existing_audio_file

SAMPLE_RATE = 16000
CLIPPED_LEVEL = 0.99   # |sample| at or above this counts as clipped
CLIPPED_SHARE = 0.01   # more than 1 % clipped samples: the transcript is flagged


@dataclass(frozen=True)
class Audio:
    samples: np.ndarray  # float32 in [-1, 1], 16 kHz mono
    source: str

    @property
    def duration_s(self) -> float:
        return len(self.samples) / SAMPLE_RATE

    @property
    def clipped_share(self) -> float:
        return float(np.mean(np.abs(self.samples) >= CLIPPED_LEVEL)) if len(self.samples) else 0.0

    def pcm16(self) -> bytes:
        """16-bit PCM bytes, the voice activity detector's input."""
        return (np.clip(self.samples, -1.0, 1.0) * 32767).astype("<i2").tobytes()


def load_audio(path: str | Path, max_duration_s: float) -> Audio:
    """The file as 16 kHz mono, or ASRError with the reason and the fix."""
    path = existing_audio_file(path)
    from faster_whisper.audio import decode_audio  # the voice extra; PyAV comes with it

    try:
        samples = decode_audio(str(path), sampling_rate=SAMPLE_RATE)
    except Exception as exc:  # PyAV raises its own error types for every broken container
        raise ASRError(f"audio file {path.name} cannot be decoded ({type(exc).__name__}: {str(exc)[:160]}); "
                       "send WAV, webm, ogg, mp3 or flac") from exc
    audio = Audio(np.asarray(samples, dtype=np.float32), path.name)
    if audio.duration_s > max_duration_s:
        raise ASRError(f"audio file {path.name} is {audio.duration_s:.0f} s long; asr.max_duration_s is "
                       f"{max_duration_s:.0f} s (raise it, or split the file)")
    return audio


def resample_pcm16(pcm: bytes, rate: int) -> bytes:
    """16-bit mono PCM at `rate` -> 16 kHz (linear interpolation: enough for VAD and the echo reference)."""
    samples = np.frombuffer(pcm, dtype="<i2").astype(np.float32)
    if rate == SAMPLE_RATE or not len(samples):
        return pcm
    count = int(round(len(samples) * SAMPLE_RATE / rate))
    positions = np.arange(count) * (rate / SAMPLE_RATE)
    return np.interp(positions, np.arange(len(samples)), samples).astype("<i2").tobytes()


def wav_pcm16(path: str | Path) -> bytes:
    """A 16-bit mono WAV (what the synthesizers write) as 16 kHz PCM, e.g. the robot's echo reference."""
    with wave.open(str(path), "rb") as audio:
        if audio.getsampwidth() != 2 or audio.getnchannels() != 1:
            raise ValueError(f"{path}: expected 16-bit mono WAV")
        return resample_pcm16(audio.readframes(audio.getnframes()), audio.getframerate())
