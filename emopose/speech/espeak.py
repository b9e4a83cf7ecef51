"""tts=espeak: local speech with true word onsets from libespeak-ng's own word events.

synthesize(reply) renders the reply once, writes <audio_dir>/<key>.wav, takes T_a from the sample
count, and maps every espeakEVENT_WORD back to character offsets of the reply (word_events.py), so
SpeechClip.onset_at_char(pos) is the engine's onset of the word at `pos`. The audio and the word events
come from one render, and every render starts from the library's freshly initialised state
(espeak_lib), so a text's render does not depend on what was rendered before. Renders are cached on
disk (<key>.wav + <key>.json with the raw events and the hash of the samples they were taken from) and in
memory; the key holds the library version, voice, rate, pitch and text, and a cached entry whose WAV
is not the audio its events came from is rendered again, so a cached clip's timings are its own.
"""

from __future__ import annotations

import hashlib
import json
import logging
import threading
from collections import OrderedDict
from pathlib import Path

from emopose.speech import espeak_lib
from emopose.speech.clip import SpeechClip
from emopose.speech.espeak_lib import WordEvent
from emopose.speech.wav import cache_dir, clip_key, read_pcm, write_wav
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
        # fail at build time, with the hint; a new library version renders differently: new cache keys
        self.sample_rate, self.engine_version = espeak_lib.engine_identity(voice, library_path)
        self._memory: OrderedDict[str, tuple[float, tuple[WordEvent, ...]]] = OrderedDict()
        self._memory_lock = threading.Lock()

    def synthesize(self, text: str) -> SpeechClip:
        if not text.strip():
            return SpeechClip(text=text, duration_s=0.0)
        key = self._key(text)
        duration, events = self._rendered(key, text)
        path = self.audio_dir / f"{key}.wav"
        return SpeechClip(text=text, duration_s=duration, words=words_from_events(text, events, duration),
                          audio_path=path if path.exists() else None)

    def word_events(self, text: str) -> tuple[WordEvent, ...]:
        """The engine's raw word events for text (the ground truth the sync evaluation measures against)."""
        if not text.strip():
            return ()
        return self._rendered(self._key(text), text)[1]

    def _key(self, text: str) -> str:
        return clip_key("espeak", self.engine_version, "fresh-state", self.voice, self.rate, self.pitch, text)

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
            if self.write_audio and raw["pcm_sha1"] != _pcm_sha1(read_pcm(wav)):
                log.warning("speech cache %s does not describe %s; re-rendering", meta, wav)
                return None
            return float(raw["duration_s"]), tuple(WordEvent(*e) for e in raw["events"])
        except (OSError, ValueError, KeyError, TypeError, EOFError) as exc:
            log.warning("ignoring unreadable speech cache %s (%s); re-rendering", meta, exc)
            return None

    def _render(self, key: str, text: str) -> tuple[float, tuple[WordEvent, ...]]:
        rendering = espeak_lib.render(text, self.voice, self.rate, self.pitch, self.library_path)
        if self.write_audio:
            write_wav(self.audio_dir / f"{key}.wav", rendering.pcm, rendering.sample_rate)
        meta = {"duration_s": rendering.duration_s, "sample_rate": rendering.sample_rate,
                "pcm_sha1": _pcm_sha1(rendering.pcm),
                "voice": self.voice, "rate": self.rate, "pitch": self.pitch,
                "events": [[e.char_index, e.length, e.audio_s] for e in rendering.events]}
        _write_text(self.audio_dir / f"{key}.json", json.dumps(meta))
        return rendering.duration_s, rendering.events


def _pcm_sha1(pcm: bytes) -> str:
    return hashlib.sha1(pcm).hexdigest()


def _write_text(path: Path, text: str) -> None:
    tmp = path.with_suffix(f".{threading.get_ident()}.tmp")
    tmp.write_text(text)
    tmp.replace(path)
