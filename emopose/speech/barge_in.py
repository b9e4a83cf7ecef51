"""Barge-in: the visitor starts speaking while the robot speaks -> one callback, never the robot itself.

Wiring (the session and turn runner own the reactions; this class only decides):
    barge = BargeIn(on_barge_in=lambda t: session.interrupt(), on_turn_end=lambda t: session.listen_done())
    player start  -> barge.robot_speaking(True);  player end/stop -> barge.robot_speaking(False)
    every microphone chunk (16 kHz int16 mono; resample_pcm16 converts) -> barge.feed(mic, reference)
where `reference` is the robot's own playback for the same stretch of time (the samples the player
sent out, resampled to 16 kHz), or None when the playback is not available to the caller.

Echo policy, while the robot speaks (a chunk must pass all that apply to count as visitor speech):
  1. a raised Silero threshold (`speaking_threshold`, default 0.8 instead of 0.5) held for a longer
     onset window (`speaking_min_speech_ms`, 160 ms): a faint or brief echo does not start speech;
  2. with a reference, a Geigel-style double-talk gate: the microphone chunk's RMS must exceed the
     loudest reference RMS of the last `echo_window_ms` (covers the loudspeaker-to-microphone delay)
     scaled by the assumed echo return loss `echo_return_loss_db` (6 dB, the classic Geigel value)
     times `echo_margin` (1.0), in at least half of the onset window's chunks and in the last one
     (speech energy dips between syllables). The robot's echo alone never passes it when the robot's
     speaker reaches its microphone at least that much quieter than the signal sent out (measure it:
     a robot whose speaker is louder at its microphone needs a real echo canceller first).
Without a reference, only (1) applies: run the microphone through an echo canceller (the browser's
getUserMedia {echoCancellation: true} does this) or accept that a loud echo can barge in. Measured
in tests/speech/test_vad_barge_in.py: echo at -12 dB self-triggers with (1) alone, never with (2).
A barge-in is reported once per robot utterance: robot_speaking(True) re-arms it. Speech events of
the visitor (start/end, for end-of-turn with the hang time) are returned by feed either way.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable

import numpy as np

from emopose.speech.vad import CHUNK_BYTES, CHUNK_S, SpeechEvent, VoiceActivity


class BargeIn:
    def __init__(self, on_barge_in: Callable[[float], None],
                 on_turn_end: Callable[[float], None] | None = None,
                 threshold: float = 0.5, speaking_threshold: float = 0.8, min_speech_ms: float = 96.0,
                 speaking_min_speech_ms: float = 160.0, hang_ms: float = 600.0,
                 echo_return_loss_db: float = 6.0, echo_margin: float = 1.0, echo_window_ms: float = 256.0,
                 detector: Callable[[bytes], float] | None = None) -> None:
        if not threshold <= speaking_threshold < 1.0:
            raise ValueError(f"barge_in.speaking_threshold must be in [threshold, 1), "
                             f"got {speaking_threshold}")
        self.on_barge_in, self.on_turn_end = on_barge_in, on_turn_end
        self.vad = VoiceActivity(threshold, min_speech_ms, hang_ms, detector)
        self.speaking_threshold = speaking_threshold
        self.speaking_min_chunks = max(1, round(speaking_min_speech_ms / 1000 / CHUNK_S))
        self.echo_gain = 10 ** (-echo_return_loss_db / 20) * echo_margin
        self._references: deque[float] = deque(maxlen=max(1, round(echo_window_ms / 1000 / CHUNK_S)))
        self._reference_buffer = b""
        self._robot = False
        self._armed = False
        self._recent: deque[tuple[float, bool, bool]] = deque(maxlen=self.speaking_min_chunks)
        self.barge_ins: list[float] = []   # stream times of every barge-in (for measurement)

    def robot_speaking(self, speaking: bool) -> None:
        """Call when the robot's audio starts (True) and when it ends or is stopped (False)."""
        self._robot, self._armed = speaking, speaking
        self._recent.clear()
        self._references.clear()
        self._reference_buffer = b""

    def feed(self, mic: bytes, reference: bytes | None = None) -> list[SpeechEvent]:
        """One stretch of microphone audio (and the robot's playback over the same stretch)."""
        if reference is not None:
            self._reference_buffer += reference
        events = []
        for t_s, chunk, probability in self.vad.scored(mic):
            echo_floor = self._next_echo_floor()
            voiced = self.vad.is_speech(probability, self.speaking_threshold if self._robot else None)
            above_echo = echo_floor is None or rms(chunk) > echo_floor
            self._check_barge_in(t_s, voiced, above_echo)
            event = self.vad.update(t_s, voiced and (above_echo or not self._robot))
            if event is not None:
                events.append(event)
                if event.kind == "end" and self.on_turn_end is not None:
                    self.on_turn_end(event.t_s)
        return events

    def _check_barge_in(self, t_s: float, voiced: bool, above_echo: bool) -> None:
        """Voiced throughout the onset window, above the echo floor in at least half of it and now."""
        if not (self._robot and self._armed):
            return
        self._recent.append((t_s, voiced, above_echo))
        window = self._recent
        if (len(window) == window.maxlen and all(v for _, v, _ in window) and above_echo
                and 2 * sum(a for _, _, a in window) >= len(window)):
            self._armed = False
            onset = next(t for t, _, a in window if a)
            self.barge_ins.append(onset)
            self.on_barge_in(onset)

    def _next_echo_floor(self) -> float | None:
        """The loudest recent reference RMS scaled by the echo gain; None without a reference."""
        if len(self._reference_buffer) < CHUNK_BYTES:
            return None if not self._references else max(self._references) * self.echo_gain
        chunk = self._reference_buffer[:CHUNK_BYTES]
        self._reference_buffer = self._reference_buffer[CHUNK_BYTES:]
        self._references.append(rms(chunk))
        return max(self._references) * self.echo_gain


def rms(pcm: bytes) -> float:
    samples = np.frombuffer(pcm, dtype="<i2").astype(np.float32) / 32768.0
    return float(np.sqrt(np.mean(samples * samples))) if len(samples) else 0.0
