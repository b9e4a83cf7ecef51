"""What a speech synthesizer returns: audio, its duration T_a, and per-word timings."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Protocol


@dataclass(frozen=True)
class WordTiming:
    """One spoken word: its characters [char_start, char_end) in the reply and its onset in the audio."""

    text: str
    char_start: int
    char_end: int
    start_s: float


@dataclass(frozen=True)
class SpeechClip:
    text: str
    duration_s: float
    words: tuple[WordTiming, ...] = ()
    audio_path: Path | None = None
    estimated: bool = False

    def onset_at_char(self, char_index: int) -> float | None:
        """Onset of the word that contains (or first follows) char_index; None without word timings."""
        for word in self.words:
            if word.char_end > char_index:
                return word.start_s
        return None


class Synthesizer(Protocol):
    name: str

    def synthesize(self, text: str) -> SpeechClip: ...


class EstimatedSpeech:
    """No TTS: duration from a speaking rate, so the paper's schedule still has a T_a (tts=none)."""

    name = "none"

    def __init__(self, words_per_minute: float = 165.0, min_duration_s: float = 0.5) -> None:
        if words_per_minute <= 0:
            raise ValueError(f"tts.words_per_minute must be positive, got {words_per_minute}")
        self.words_per_minute = words_per_minute
        self.min_duration_s = min_duration_s

    def synthesize(self, text: str) -> SpeechClip:
        words = len(text.split())
        duration = max(self.min_duration_s, 60.0 * words / self.words_per_minute) if words else 0.0
        return SpeechClip(text=text, duration_s=duration, estimated=True)
