"""tts=piper (#32): synthesis real-time factor, and its word onsets against whisper's word timestamps.

Each sentence of benchmarks/data/listen/sentences.txt is synthesized by PiperSynthesizer (the packaged
voice, a fresh audio folder so nothing comes from the cache; the first render is a warm-up, not
counted) and transcribed by asr=whisper (tiny.en) with word timestamps. Words of the reply and of the
transcript are paired in order by their normalised text (difflib); for every pair the onset error is
piper's onset minus whisper's word start. The same is done for espeak, whose onsets are the engine's own
word events (ground truth): its error is the error of the whisper check itself, so piper's error is
read next to it. Targets (issue 32): onsets within 40 ms, synthesis real-time factor <= 0.5.
Run: python benchmarks/piper_timing.py [--limit N] -> JSON on stdout.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from difflib import SequenceMatcher
from pathlib import Path

import numpy as np

from emopose.speech.espeak import EspeakSynthesizer
from emopose.speech.piper_tts import PiperSynthesizer
from emopose.speech.wer import normalise
from emopose.speech.whisper_asr import WhisperTranscriber

SENTENCES = Path(__file__).parent / "data" / "listen" / "sentences.txt"


def onset_errors(clip, heard) -> list[float]:
    """Piper/espeak onset - whisper start, for the words both sides agree on (one token each)."""
    spoken = [(normalise(w.text), w.start_s) for w in clip.words]
    spoken = [(words[0], t) for words, t in spoken if len(words) == 1]
    found = [(normalise(w.text), w.start_s) for w in heard.words]
    found = [(words[0], t) for words, t in found if len(words) == 1]
    matcher = SequenceMatcher(None, [w for w, _ in spoken], [w for w, _ in found], autojunk=False)
    return [spoken[b.a + i][1] - found[b.b + i][1]
            for b in matcher.get_matching_blocks() for i in range(b.size)]


def summary(errors: list[float]) -> dict:
    absolute = np.abs(errors) * 1000
    return {"words": len(errors), "median_abs_ms": float(np.median(absolute)),
            "p90_abs_ms": float(np.percentile(absolute, 90)),
            "p95_abs_ms": float(np.percentile(absolute, 95)),
            "mean_signed_ms": float(np.mean(errors) * 1000), "within_40ms": float(np.mean(absolute <= 40))}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--limit", type=int, default=None)
    args = parser.parse_args()
    lines = [s.strip() for s in SENTENCES.read_text().splitlines() if s.strip()][:args.limit]
    folder = tempfile.mkdtemp(prefix="emopose-piper-")
    started = time.perf_counter()
    piper = PiperSynthesizer(audio_dir=folder)
    load_s = time.perf_counter() - started
    espeak, asr = EspeakSynthesizer(audio_dir=folder), WhisperTranscriber()
    piper.synthesize("Warming up the voice.")
    synth_s, audio_s, errors = 0.0, 0.0, {"piper": [], "espeak": []}
    for line in lines:
        started = time.perf_counter()
        clip = piper.synthesize(line)
        synth_s, audio_s = synth_s + time.perf_counter() - started, audio_s + clip.duration_s
        for name, spoken in (("piper", clip), ("espeak", espeak.synthesize(line))):
            errors[name] += onset_errors(spoken, asr.transcribe_detail(spoken.audio_path))
    print(json.dumps({"sentences": len(lines), "voice_load_s": load_s, "synthesis_rtf": synth_s / audio_s,
                      "audio_s": audio_s, "piper_vs_whisper": summary(errors["piper"]),
                      "espeak_vs_whisper (the check's own error)": summary(errors["espeak"])}, indent=2))


if __name__ == "__main__":
    main()
