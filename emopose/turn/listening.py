"""Listener: the visitor's microphone in a live session, heard while the robot talks and between turns.

    listener = Listener(settings.detector(), clock, speaking=lambda: player.playing(clock),
                        silence=runner.silence, utterances=Utterances(barge.vad, folder, on_utterance),
                        reference=PlaybackReference(player))      # reference: only where the echo is raw
    listener.feed(pcm)          # each stretch of 16 kHz mono int16 as it arrives (any length, any thread)

Each feed tells the detector whether the robot's audio is playing (player.playing: it turns False the
moment the player stops), hands it the robot's own playback over the same stretch as the echo
reference, and passes the speech events on to `utterances`, which hands each finished utterance (VAD
end after the hang time) on as a WAV. A barge-in calls `silence` once (the runner's silence(): the
reply stops streaming, the player stops, on player=g1 with stop play 1004, the sequencer is
interrupted and the arms blend to rest) and records when, on the caller's clock, in `barge_ins`.
With `early` (speech/early_asr.py), a pause in the visitor's speech starts transcribing it, so at the
VAD end `early.transcript(path)` is mostly ready. Stream time maps to clock time from the first feed on
(`at` gives a feed's clock time explicitly: a job feeding recorded audio on virtual time).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass

from emopose.clock import Clock
from emopose.speech.audio_in import SAMPLE_RATE
from emopose.speech.barge_in import BargeIn
from emopose.speech.early_asr import EarlyTranscripts
from emopose.speech.g1_microphone import Utterances
from emopose.speech.vad import SpeechEvent

BYTES_PER_S = 2 * SAMPLE_RATE


@dataclass(frozen=True)
class BargeInRecord:
    onset_s: float     # clock time the detector places the visitor's voice onset at
    detected_s: float  # clock time it decided (the end of the chunk that completed its onset window)
    stopped_s: float   # clock time silence() had returned: the audio stopped, the sequencer interrupted


class Listener:
    def __init__(self, barge: BargeIn, clock: Clock, speaking: Callable[[], bool],
                 silence: Callable[[], None], utterances: Utterances | None = None,
                 reference: Callable[[float, int], bytes | None] | None = None,
                 early: EarlyTranscripts | None = None) -> None:
        self.barge, self.clock, self.speaking, self.silence = barge, clock, speaking, silence
        self.utterances, self.reference, self.early = utterances, reference, early
        barge.on_barge_in = self._barge_in
        self.barge_ins: list[BargeInRecord] = []
        self._robot = False
        self._origin: float | None = None  # clock time of stream time 0
        self._fed_bytes = 0
        self._lock = threading.Lock()      # the page's socket and the robot's microphone may both feed

    @property
    def visitor_speaking(self) -> bool:
        return self.barge.vad.speaking

    def clock_time(self, stream_s: float) -> float:
        return (self._origin or 0.0) + stream_s

    def feed(self, pcm: bytes, at: float | None = None) -> list[SpeechEvent]:
        """Microphone PCM; `at` is the clock time of its first sample (default: it ended just now)."""
        pcm = pcm[: len(pcm) - len(pcm) % 2]
        with self._lock:
            stream_s = self._fed_bytes / BYTES_PER_S
            if self._origin is None:
                start = self.clock.now() - len(pcm) / BYTES_PER_S if at is None else at
                self._origin = start - stream_s
            speaking = self.speaking()
            if speaking != self._robot:
                self._robot = speaking
                self.barge.robot_speaking(speaking)
            reference = None
            if speaking and self.reference is not None:
                reference = self.reference(self.clock_time(stream_s), len(pcm))
            self._fed_bytes += len(pcm)
            events = self.barge.feed(pcm, reference)
            if self.utterances is not None:
                self.utterances.take(pcm, events)
                if self.early is not None:
                    self.early.consider(self.barge.vad, self.utterances)
            return events

    def _barge_in(self, onset_stream_s: float) -> None:
        detected = self.clock_time(self.barge.vad.t_s)
        self.silence()
        self.barge_ins.append(BargeInRecord(self.clock_time(onset_stream_s), detected, self.clock.now()))
