"""tts=espeak: local speech with true word onsets from libespeak-ng's own word events.

synthesize(reply) renders the reply once, writes <audio_dir>/<key>.wav, takes T_a from the sample
count, and maps every espeakEVENT_WORD back to character offsets of the reply (word_events.py), so
SpeechClip.onset_at_char(pos) is the engine's onset of the word at `pos`. Renders are cached on disk
(<key>.wav + <key>.json with the raw events) and in memory: espeak is deterministic for a given
voice, rate, pitch and text, and the schedule and the sync evaluation ask for the same reply twice.
"""

from __future__ import annotations

import json
import logging
import threading
from collections import OrderedDict
from pathlib import Path

from emopose.speech import espeak_lib
from emopose.speech.clip import SpeechClip
from emopose.speech.espeak_lib import WordEvent
from emopose.speech.wav import cache_dir, clip_key, write_wav
from emopose.speech.word_events import words_from_events

log = logging.getLogger(__name__)

RATE_RANGE = (80, 450)  # espeakRATE_MINIMUM .. espeakRATE_MAXIMUM, words per minute
PITCH_RANGE = (0, 100)
MEMORY_ITEMS = 256


class EspeakSynthesizer:
    name = "espeak"

    def __init__(self, voice: str = "en-us", rate: int = 165, pitch: int = 50, audio_dir: str | None = None,
                 write_audio: bool = True, library_path: str | None = None) -> None:
        if not RATE_RANGE[0] <= rate <= RATE_RANGE[1]:
            raise ValueError(f"tts.rate must be {RATE_RANGE[0]}..{RATE_RANGE[1]} words per minute, "
                             f"got {rate}")
        if not PITCH_RANGE[0] <= pitch <= PITCH_RANGE[1]:
            raise ValueError(f"tts.pitch must be {PITCH_RANGE[0]}..{PITCH_RANGE[1]} (50 = normal), "
                             f"got {pitch}")
        self.voice, self.rate, self.pitch = voice, int(rate), int(pitch)
        self.library_path = library_path
        self.write_audio = write_audio
        self.audio_dir = cache_dir(audio_dir, "tts.audio_dir")
        self.sample_rate = espeak_lib.engine_sample_rate(library_path)  # fail at build time, with the hint
        espeak_lib.check_voice(voice, library_path)
        self._memory: OrderedDict[str, tuple[float, tuple[WordEvent, ...]]] = OrderedDict()
        self._memory_lock = threading.Lock()

    def synthesize(self, text: str) -> SpeechClip:
        if not text.strip():
            return SpeechClip(text=text, duration_s=0.0)
        key = clip_key("espeak", self.voice, self.rate, self.pitch, text)
        duration, events = self._rendered(key, text)
        path = self.audio_dir / f"{key}.wav"
        return SpeechClip(text=text, duration_s=duration, words=words_from_events(text, events, duration),
                          audio_path=path if path.exists() else None)

    def word_events(self, text: str) -> tuple[WordEvent, ...]:
        """The engine's raw word events for text (the ground truth the sync evaluation measures against)."""
        if not text.strip():
            return ()
        return self._rendered(clip_key("espeak", self.voice, self.rate, self.pitch, text), text)[1]

    # -- rendering and the two caches ----------------------------------------------------------
    def _rendered(self, key: str, text: str) -> tuple[float, tuple[WordEvent, ...]]:
        with self._memory_lock:
            if key in self._memory:
                self._memory.move_to_end(key)
                return self._memory[key]
        result = self._from_disk(key) or self._render(key, text)
        with self._memory_lock:
            self._memory[key] = result
            while len(self._memory) > MEMORY_ITEMS:
                self._memory.popitem(last=False)
        return result

    def _from_disk(self, key: str) -> tuple[float, tuple[WordEvent, ...]] | None:
        meta, wav = self.audio_dir / f"{key}.json", self.audio_dir / f"{key}.wav"
        if not meta.exists() or (self.write_audio and not wav.exists()):
            return None
        try:
            raw = json.loads(meta.read_text())
            return float(raw["duration_s"]), tuple(WordEvent(*e) for e in raw["events"])
        except (OSError, ValueError, KeyError, TypeError) as exc:
            log.warning("ignoring unreadable speech cache %s (%s); re-rendering", meta, exc)
            return None

    def _render(self, key: str, text: str) -> tuple[float, tuple[WordEvent, ...]]:
        rendering = espeak_lib.render(text, self.voice, self.rate, self.pitch, self.library_path)
        if self.write_audio:
            write_wav(self.audio_dir / f"{key}.wav", rendering.pcm, rendering.sample_rate)
        meta = {"duration_s": rendering.duration_s, "sample_rate": rendering.sample_rate,
                "voice": self.voice, "rate": self.rate, "pitch": self.pitch,
                "events": [[e.char_index, e.length, e.audio_s] for e in rendering.events]}
        _write_text(self.audio_dir / f"{key}.json", json.dumps(meta))
        return rendering.duration_s, rendering.events


def _write_text(path: Path, text: str) -> None:
    tmp = path.with_suffix(f".{threading.get_ident()}.tmp")
    tmp.write_text(text)
    tmp.replace(path)
