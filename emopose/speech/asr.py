"""Speech recognition for the user's side of a turn: asr=none (typed text), asr=litellm (any model);
asr=whisper (local, emopose/speech/whisper_asr.py) offers the same interface.

Both offer `utterance(text=None, audio=None) -> str`: typed text passes through unchanged; an audio file
is transcribed (asr=litellm) or refused with the fix (asr=none). litellm.transcription posts the file
to `{api_base}/audio/transcriptions` (OpenAI-compatible servers, whisper.cpp, vLLM, hosted providers).
"""

from __future__ import annotations

import logging
import time
from abc import ABC, abstractmethod
from pathlib import Path

from emopose.llm.client import effective_api_key
from emopose.llm.errors import litellm_module

log = logging.getLogger(__name__)

AUDIO_SUFFIXES = (".wav", ".mp3", ".m4a", ".ogg", ".oga", ".flac", ".webm", ".mp4", ".mpeg", ".mpga")


class ASRError(RuntimeError):
    """An utterance could not be obtained; the message names the config key or file to fix."""


def existing_audio_file(audio: str | Path) -> Path:
    """The path of an audio file that exists and has a suffix we decode, or ASRError saying which."""
    path = Path(audio)
    if not path.is_file():
        raise ASRError(f"audio file {path} does not exist")
    if path.suffix.lower() not in AUDIO_SUFFIXES:
        raise ASRError(f"audio file {path.name} has suffix {path.suffix!r}; "
                       f"use one of {', '.join(AUDIO_SUFFIXES)}")
    return path


class Recognizer(ABC):
    name = "base"
    accepts_audio = True  # False: typed text only (the web page then hides its microphone)
    listening: dict = {}  # how a live session hears the visitor: asr.listening (speech/listening.py)

    def utterance(self, text: str | None = None, audio: str | Path | None = None) -> str:
        """Typed text wins; otherwise the transcript of `audio`."""
        if text is not None and text.strip():
            return text.strip()
        if audio is None:
            raise ASRError("no utterance: give typed text or an audio file")
        return self.transcribe(audio)

    @abstractmethod
    def transcribe(self, audio: str | Path) -> str:
        """The transcript of an audio file."""


class TypedText(Recognizer):
    """asr=none: the user types; audio input is refused with the way to enable it."""

    name = "none"
    accepts_audio = False

    def transcribe(self, audio: str | Path) -> str:
        raise ASRError(f"asr=none cannot transcribe {audio}: type the utterance, or run with "
                       "asr=whisper (local) or asr=litellm")


class LitellmTranscriber(Recognizer):
    """asr=litellm: litellm.transcription against any model and endpoint."""

    name = "litellm"

    def __init__(self, model: str = "openai/whisper-1", api_base: str | None = None,
                 api_key: str | None = None, language: str | None = "en", prompt: str | None = None,
                 timeout_s: float = 30.0, listening: dict | None = None) -> None:
        self.listening = dict(listening or {})
        if not model:
            raise ValueError("asr.model is empty: name a litellm transcription model, e.g. openai/whisper-1")
        self.model, self.api_base, self.api_key = model, api_base, api_key
        self.language, self.prompt, self.timeout_s = language, prompt, timeout_s
        self.last_latency_s: float | None = None

    def transcribe(self, audio: str | Path) -> str:
        path = existing_audio_file(audio)
        litellm = litellm_module()  # heavy import, only when audio is transcribed
        optional = {k: v for k, v in (("language", self.language), ("prompt", self.prompt)) if v}
        started = time.perf_counter()
        try:
            key = effective_api_key(litellm, self.model, self.api_base, self.api_key)  # a keyless server too
            with path.open("rb") as handle:
                response = litellm.transcription(model=self.model, file=handle, api_base=self.api_base,
                                                 api_key=key, timeout=self.timeout_s, **optional)
        except Exception as exc:
            where = self.api_base or "provider default"
            raise ASRError(f"transcription of {path.name} by {self.model} at {where} failed: "
                           f"{type(exc).__name__}: {str(exc)[:300]} (check asr.model, asr.api_base, "
                           "asr.api_key)") from exc
        self.last_latency_s = time.perf_counter() - started
        text = (getattr(response, "text", None) or "").strip()
        log.info("transcribed %s in %.2f s: %r", path.name, self.last_latency_s, text[:80])
        return text

