"""What the robot said, as recording channels: the player hands every clip it starts to SpeechRecording.

`/speech/said` holds each clip once (its start on the play clock, duration and text: the captions of a
video, with or without TTS audio); `/speech/audio` holds its samples, when the clip has a WAV, in chunks
of CHUNK_S as PCM16 (Foxglove's RawAudio fields: format, sample_rate, number_of_channels, base64 data),
each at the play-clock time it is heard. A clip is recorded as started: when a later clip or an
interrupt cuts it short, the rest of its samples are in the file all the same (the cut is on
/sequencer/events and the next clip's start). A WAV that cannot be read is logged and only `/speech/said`
is written: recording never stops the speech.
"""

from __future__ import annotations

import base64
import logging
import wave
from collections.abc import Callable, Iterator
from pathlib import Path

from emopose.speech.clip import SpeechClip

log = logging.getLogger(__name__)

AUDIO, SAID = "/speech/audio", "/speech/said"
CHUNK_S = 0.5
PCM16 = "pcm-s16"

# record(topic, clock_time, payload): the message is recorded at that play-clock time, as its `t`
Record = Callable[[str, float, dict], None]


def audio_chunks(path: Path, chunk_s: float = CHUNK_S) -> Iterator[dict]:
    """The WAV's samples as /speech/audio payloads without `t`, each with its offset into the clip."""
    with wave.open(str(path), "rb") as audio:
        if audio.getsampwidth() != 2:
            raise ValueError(f"{path}: {8 * audio.getsampwidth()}-bit samples; the channel holds 16-bit PCM")
        rate, channels = audio.getframerate(), audio.getnchannels()
        step = max(1, int(rate * chunk_s))
        for first in range(0, audio.getnframes(), step):
            data = audio.readframes(step)
            yield {"offset_s": first / rate, "format": PCM16, "sample_rate": rate,
                   "number_of_channels": channels, "data": base64.b64encode(data).decode("ascii")}


class SpeechRecording:
    """The Player's on_play: records each started clip on /speech/said and its samples on /speech/audio."""

    def __init__(self, record: Record) -> None:
        self.record = record

    def __call__(self, clip: SpeechClip, start: float) -> None:
        self.record(SAID, start, {"text": clip.text, "duration_s": clip.duration_s,
                                  "audio": clip.audio_path is not None})
        if clip.audio_path is None:
            return
        try:
            chunks = list(audio_chunks(Path(clip.audio_path)))
        except (OSError, EOFError, ValueError, wave.Error) as exc:
            log.warning("speech audio not recorded: %s", exc)
            return
        for chunk in chunks:
            self.record(AUDIO, start + chunk["offset_s"], chunk)
