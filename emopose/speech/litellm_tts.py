"""tts=litellm: hosted speech through litellm.speech, with estimated word timings.

A hosted engine returns audio but no word events, so the clip is flagged `estimated=True` and its word
onsets are estimated: espeak renders the same reply locally (a few ms), and its relative word onsets
are stretched to the hosted duration, which follows pauses and long numbers far better than spreading
characters evenly (the fallback when espeak is not installed either). Any failure of the hosted call
(network, auth, a non-WAV answer) logs a warning and returns the local espeak clip instead, so a turn
always has speech.
"""

from __future__ import annotations

import logging
import re
from pathlib import Path

from emopose.llm.client import effective_api_key
from emopose.llm.errors import litellm_module
from emopose.speech.clip import SpeechClip, WordTiming
from emopose.speech.espeak import EspeakSynthesizer
from emopose.speech.espeak_lib import EspeakUnavailable
from emopose.speech.wav import cache_dir, clip_key, wav_duration

log = logging.getLogger(__name__)


class LitellmSpeech:
    name = "litellm"

    def __init__(self, model: str = "openai/gpt-4o-mini-tts", voice: str = "alloy",
                 api_base: str | None = None, api_key: str | None = None, timeout_s: float = 30.0,
                 audio_dir: str | None = None, fallback: dict | None = None) -> None:
        if not model:
            raise ValueError("tts.model is empty: name a litellm speech model, e.g. openai/gpt-4o-mini-tts")
        self.model, self.voice, self.api_base, self.api_key = model, voice, api_base, api_key
        self.timeout_s = timeout_s
        self.audio_dir = cache_dir(audio_dir, "tts.audio_dir")
        self.fallback_kwargs = dict(fallback or {})
        self._local: EspeakSynthesizer | None | bool = None  # None: not tried yet; False: unavailable

    def synthesize(self, text: str) -> SpeechClip:
        if not text.strip():
            return SpeechClip(text=text, duration_s=0.0, estimated=True)
        try:
            path, duration = self._hosted(text)
        except Exception as exc:  # any hosted failure: speak locally rather than lose the turn's speech
            local = self._espeak()
            if local is None:
                raise RuntimeError(
                    f"hosted TTS {self.model} failed ({exc}) and espeak-ng is not available"
                ) from exc
            log.warning("hosted TTS %s failed (%s: %s); falling back to espeak", self.model,
                        type(exc).__name__, str(exc)[:200])
            return local.synthesize(text)
        return SpeechClip(text=text, duration_s=duration, words=self._estimate_words(text, duration),
                          audio_path=path, estimated=True)

    def _hosted(self, text: str) -> tuple[Path, float]:
        litellm = litellm_module()  # heavy import, only when hosted speech is used
        key = effective_api_key(litellm, self.model, self.api_base, self.api_key)  # a keyless server too
        response = litellm.speech(model=self.model, input=text, voice=self.voice, api_base=self.api_base,
                                  api_key=key, response_format="wav", timeout=self.timeout_s)
        audio = response.content
        duration = wav_duration(audio)  # raises on a non-WAV answer: T_a must come from real samples
        path = self.audio_dir / f"{clip_key('litellm', self.model, self.voice, text)}.wav"
        path.write_bytes(audio)
        return path, duration

    def _espeak(self) -> EspeakSynthesizer | None:
        if self._local is None:
            try:
                self._local = EspeakSynthesizer(**{"audio_dir": str(self.audio_dir), **self.fallback_kwargs})
            except EspeakUnavailable as exc:
                log.warning("no local espeak for fallback/word estimates: %s", exc)
                self._local = False
        return self._local or None

    def _estimate_words(self, text: str, duration_s: float) -> tuple[WordTiming, ...]:
        local = self._espeak()
        if local is not None:
            reference = local.synthesize(text)
            if reference.words and reference.duration_s > 0:
                scale = duration_s / reference.duration_s
                return tuple(WordTiming(w.text, w.char_start, w.char_end, min(w.start_s * scale, duration_s))
                             for w in reference.words)
        return proportional_words(text, duration_s)


def proportional_words(text: str, duration_s: float) -> tuple[WordTiming, ...]:
    """Onsets spread by character position over the whole duration (the paper's anchor assumption)."""
    length = max(len(text), 1)
    return tuple(WordTiming(m.group(), m.start(), m.end(), m.start() / length * duration_s)
                 for m in re.finditer(r"\S+", text))
