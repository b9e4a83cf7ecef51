"""How a live session hears the visitor: where the microphone comes from, VAD, barge-in and its echo gate.

The settings live under the recognizer (`asr.listening`, conf/asr/whisper.yaml and litellm.yaml): only a
session that transcribes speech listens. `audio_source`:
  page  the web page streams its microphone over the WebSocket (binary messages, 16 kHz mono int16;
        the browser's echo canceller cleans it, so the gate is the raised threshold alone);
  g1    the robot's microphone multicast (emopose/speech/g1_microphone.py), with the robot's own
        playback as the echo gate's reference (barge_in.py's double-talk gate).
`hang_ms` is the silence that ends the visitor's turn; the barge-in settings are BargeIn's.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, fields
from pathlib import Path

from emopose.speech.audio_in import SAMPLE_RATE, wav_pcm16
from emopose.speech.barge_in import BargeIn
from emopose.speech.echo import EchoGate
from emopose.speech.g1_microphone import MIC_GROUP, MIC_PORT

AUDIO_SOURCES = ("page", "g1")


@dataclass(frozen=True)
class ListeningSettings:
    audio_source: str = "page"
    threshold: float = 0.5
    min_speech_ms: float = 96.0
    hang_ms: float = 600.0
    barge_in: bool = True               # false: the visitor's voice while the robot speaks is ignored
    speaking_threshold: float = 0.8
    speaking_min_speech_ms: float = 160.0
    echo_return_loss_db: float = 6.0
    echo_margin_db: float = 10.0
    double_talk_min_speech_ms: float = 96.0
    early_transcribe_ms: float | None = None  # a pause this long starts transcribing (None: at VAD end)
    # A spoken reply's speech waits at most this long for its first gesture's preparation (the timeline's
    # pre-roll, 0.4 s for typed input): the visitor has already waited through the hang time and the
    # transcription. A first gesture that needs longer is softened or comes late (stages/softening.py).
    reply_preroll_s: float = 0.2
    mic_group: str | None = MIC_GROUP   # audio_source=g1: the robot's multicast group (null: plain UDP)
    mic_port: int = MIC_PORT
    mic_interface_ip: str = "0.0.0.0"   # our address on the robot's network

    def __post_init__(self) -> None:
        if self.reply_preroll_s < 0:
            raise ValueError(f"asr.listening.reply_preroll_s must be >= 0, got {self.reply_preroll_s}")
        if self.audio_source not in AUDIO_SOURCES:
            raise ValueError(f"asr.listening.audio_source must be one of {AUDIO_SOURCES}, "
                             f"got {self.audio_source!r}")

    @classmethod
    def from_config(cls, node: dict | None) -> ListeningSettings:
        values = dict(node or {})
        unknown = set(values) - {f.name for f in fields(cls)}
        if unknown:
            raise ValueError(f"asr.listening: unknown setting(s) {sorted(unknown)}")
        return cls(**values)

    def detector(self, detector: Callable[[bytes], float] | None = None,
                 echo: EchoGate | None = None) -> BargeIn:
        """A BargeIn with these settings (its on_barge_in is set by whoever reacts: turn/listening.py);
        `echo`: the room a previous one learned (speech/echo.py)."""
        return BargeIn(on_barge_in=lambda t: None, threshold=self.threshold,
                       speaking_threshold=self.speaking_threshold, min_speech_ms=self.min_speech_ms,
                       speaking_min_speech_ms=self.speaking_min_speech_ms, hang_ms=self.hang_ms,
                       echo_return_loss_db=self.echo_return_loss_db, echo_margin_db=self.echo_margin_db,
                       double_talk_min_speech_ms=self.double_talk_min_speech_ms, detector=detector,
                       echo=echo)


class PlaybackReference:
    """The player's own output over a stretch of clock time, 16 kHz PCM: the echo gate's reference.

    reference(t, n_bytes) is the clip started last (`player.clip`, heard from `player.started_at`) from
    clock time t on, zeros outside it; None when nothing was played."""

    def __init__(self, player) -> None:
        self.player = player
        self._cached: tuple[Path, bytes] | None = None

    def __call__(self, t: float, n_bytes: int) -> bytes | None:
        clip, start = self.player.clip, self.player.started_at
        if clip is None or start is None or clip.audio_path is None:
            return None
        pcm = self._pcm(Path(clip.audio_path))
        first = 2 * round((t - start) * SAMPLE_RATE)
        out = bytearray(n_bytes)
        a, b = max(first, 0), min(first + n_bytes, len(pcm))
        if a < b:
            out[a - first:b - first] = pcm[a:b]
        return bytes(out)

    def _pcm(self, path: Path) -> bytes:
        if self._cached is None or self._cached[0] != path:
            self._cached = (path, wav_pcm16(path))
        return self._cached[1]
