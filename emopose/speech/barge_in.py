"""Barge-in: the visitor starts speaking while the robot speaks -> one callback, never the robot itself.

Wiring (the session and turn runner own the reactions; this class only decides):
    barge = BargeIn(on_barge_in=lambda t: session.interrupt(), on_turn_end=lambda t: session.listen_done())
    player start  -> barge.robot_speaking(True);  player end/stop -> barge.robot_speaking(False)
    every microphone chunk (16 kHz int16 mono; resample_pcm16 converts) -> barge.feed(mic, reference)
where `reference` is the robot's own playback for the same stretch of time (the samples the player
sent out, resampled to 16 kHz; padded with silence or cut to the microphone's length), or None when
the playback is not available to the caller (treated as silence once a reference has been seen).

Echo policy, while the robot speaks (a chunk must pass all that apply to count as visitor speech):
  1. a raised Silero threshold (`speaking_threshold`, default 0.8 instead of 0.5) held for a longer
     onset window (`speaking_min_speech_ms`, 160 ms): a faint or brief echo does not start speech;
  2. with a reference (emopose/speech/echo.py): an adaptive echo canceller removes the robot's voice
     from the microphone and Silero hears the residual; a double-talk gate requires the residual to be
     louder than the echo can be: the loudest reference RMS of the last `echo_window_ms` times a
     coupling gain that starts at the Geigel assumption (echo `echo_return_loss_db`, 6 dB, down) and
     falls to `echo_margin_db` (10 dB) above the residual coupling measured while the robot talks alone. The
     residual must pass it in at least half of the onset window's chunks and in the last one. Once
     the gate has learned the room, the window shrinks to `double_talk_min_speech_ms` (96 ms).
Without a reference, only (1) applies: run the microphone through an echo canceller (the browser's
getUserMedia {echoCancellation: true} does this) or accept that a loud echo can barge in. Measured
in tests/speech/test_vad_barge_in.py with an echo through a room response (delay, reflections).
A barge-in is reported once per robot utterance: robot_speaking(True) re-arms it. Speech events of
the visitor (start/end, for end-of-turn with the hang time) are returned by feed either way.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable

import numpy as np

from emopose.speech.echo import EchoGate
from emopose.speech.vad import CHUNK_BYTES, CHUNK_S, CHUNK_SAMPLES, SpeechEvent, VoiceActivity


class BargeIn:
    def __init__(self, on_barge_in: Callable[[float], None],
                 on_turn_end: Callable[[float], None] | None = None,
                 threshold: float = 0.5, speaking_threshold: float = 0.8, min_speech_ms: float = 96.0,
                 speaking_min_speech_ms: float = 160.0, hang_ms: float = 600.0,
                 echo_return_loss_db: float = 6.0, echo_margin_db: float = 10.0,
                 echo_window_ms: float = 256.0, double_talk_min_speech_ms: float = 96.0,
                 detector: Callable[[bytes], float] | None = None, echo: EchoGate | None = None) -> None:
        if not threshold <= speaking_threshold < 1.0:
            raise ValueError(f"barge_in.speaking_threshold must be in [threshold, 1), "
                             f"got {speaking_threshold}")
        self.on_barge_in, self.on_turn_end = on_barge_in, on_turn_end
        self.vad = VoiceActivity(threshold, min_speech_ms, hang_ms, detector)
        self.speaking_threshold = speaking_threshold
        self.window_chunks = max(1, round(speaking_min_speech_ms / 1000 / CHUNK_S))
        self.learned_window_chunks = max(1, round(double_talk_min_speech_ms / 1000 / CHUNK_S))
        # one per microphone and loudspeaker: pass the previous BargeIn's `echo` to keep what it learned
        self.echo = echo or EchoGate(CHUNK_SAMPLES, echo_return_loss_db, echo_margin_db, echo_window_ms)
        self._mic, self._reference = b"", b""
        self._with_reference = False
        self._robot = False
        self._armed = False
        self._recent: deque[tuple[float, bool, bool]] = deque(maxlen=self.window_chunks)
        self.barge_ins: list[float] = []   # stream times of every barge-in (for measurement)

    def robot_speaking(self, speaking: bool) -> None:
        """Call when the robot's audio starts (True) and when it ends or is stopped (False)."""
        self._robot, self._armed = speaking, speaking
        self._recent.clear()
        self.echo.forget_reference()

    def feed(self, mic: bytes, reference: bytes | None = None) -> list[SpeechEvent]:
        """One stretch of microphone audio (and the robot's playback over the same stretch)."""
        if reference is not None and not self._with_reference:
            # the microphone samples still waiting for a whole chunk were heard with no robot playing
            self._with_reference, self._reference = True, bytes(len(self._mic))
        self._mic += mic
        if self._with_reference:
            reference = (reference or b"")[:len(mic)]
            self._reference += reference + bytes(len(mic) - len(reference))
        events = []
        while len(self._mic) >= CHUNK_BYTES:
            chunk, self._mic = self._mic[:CHUNK_BYTES], self._mic[CHUNK_BYTES:]
            event = self._chunk(chunk)
            if event is not None:
                events.append(event)
                if event.kind == "end" and self.on_turn_end is not None:
                    self.on_turn_end(event.t_s)
        return events

    def _chunk(self, chunk: bytes) -> SpeechEvent | None:
        above_echo = True
        if self._with_reference:
            reference, self._reference = self._reference[:CHUNK_BYTES], self._reference[CHUNK_BYTES:]
            residual = self.echo.residual(samples(chunk), samples(reference))
            chunk = np.clip(residual * 32768.0, -32768, 32767).astype("<i2").tobytes()
            above_echo = self.echo.above_floor()
        t_s, probability = self.vad.score(chunk)
        raised = self._robot and not self.echo.learned  # a learned gate tells echo from voice by itself
        voiced = self.vad.is_speech(probability, self.speaking_threshold if raised else None)
        if self._with_reference:
            self.echo.learn(double_talk=self._robot and voiced and above_echo)
        self._check_barge_in(t_s, voiced, above_echo)
        return self.vad.update(t_s, voiced and (above_echo or not self._robot))

    def _check_barge_in(self, t_s: float, voiced: bool, above_echo: bool) -> None:
        """Voiced throughout the onset window, above the echo floor in at least half of it and now."""
        if not (self._robot and self._armed):
            return
        self._recent.append((t_s, voiced, above_echo))
        needed = self.learned_window_chunks if self.echo.learned else self.window_chunks
        window = list(self._recent)[-needed:]
        if (len(window) == needed and all(v for _, v, _ in window) and above_echo
                and 2 * sum(a for _, _, a in window) >= len(window)):
            self._armed = False
            onset = next(t for t, _, a in window if a)
            self.barge_ins.append(onset)
            self.on_barge_in(onset)


def samples(pcm: bytes) -> np.ndarray:
    return np.frombuffer(pcm, dtype="<i2").astype(np.float64) / 32768.0
