"""tts=piper (#32): are piper's word onsets within 40 ms of the audio's word boundaries? Two checks.

benchmarks/piper_timing.py compares piper's onsets with whisper's word starts, but whisper (tiny.en)
starts words ~90 ms late on espeak, whose onsets are the engine's own events, so that raw comparison
cannot verify 40 ms. Here the same sentences are rendered by both engines (piper: the packaged voice;
espeak: en-us, 165 wpm) and checked two ways:
  whisper, bias-corrected per word: for each word both engines and both transcripts agree on, piper's
      error against whisper minus espeak's error against whisper for the same word of the same sentence
      (whisper's bias depends on the word's sounds, which both voices share; espeak's error is pure
      whisper bias because its onsets are true);
  pauses in the audio (no whisper): every rise from >= --pause-s (each value given) of silence (frame
      RMS below --floor-db of the loudest 10 ms frame) to sound is a word start; each is paired with
      the engine's nearest onset within 250 ms. Run on espeak the same measure shows the check's own error.
Run: python benchmarks/piper_onsets.py [--limit N] -> JSON on stdout (a few minutes on 2 cores).
"""

from __future__ import annotations

import argparse
import itertools
import json
import sys
import tempfile
import wave
from difflib import SequenceMatcher
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout without installing

from emopose.speech.espeak import EspeakSynthesizer
from emopose.speech.piper_tts import PiperSynthesizer
from emopose.speech.wer import normalise
from emopose.speech.whisper_asr import WhisperTranscriber

SENTENCES = Path(__file__).parent / "data" / "listen" / "sentences.txt"
HOP_S = 0.005
PAIR_S = 0.25
TARGET_MS = 40.0


def whisper_errors(clip, heard) -> dict[int, float]:
    """A word's char_start -> the engine's onset minus whisper's start, for words matched one to one."""
    spoken = [(normalise(w.text), w.char_start, w.start_s) for w in clip.words]
    spoken = [(words[0], char, t) for words, char, t in spoken if len(words) == 1]
    found = [(normalise(w.text), w.start_s) for w in heard.words]
    found = [(words[0], t) for words, t in found if len(words) == 1]
    matcher = SequenceMatcher(None, [w for w, _, _ in spoken], [w for w, _ in found], autojunk=False)
    return {spoken[b.a + i][1]: spoken[b.a + i][2] - found[b.b + i][1]
            for b in matcher.get_matching_blocks() for i in range(b.size)}


def pause_onsets(path: Path, pause_s: float, floor_db: float) -> list[float]:
    """Times at which sound starts after at least pause_s of silence (the clip's start counts as silence)."""
    with wave.open(str(path), "rb") as audio:
        rate = audio.getframerate()
        samples = np.frombuffer(audio.readframes(-1), "<i2").astype(np.float64)
    hop = max(1, round(rate * HOP_S))
    frames = np.array([np.sqrt(np.mean(samples[i:i + 2 * hop] ** 2))
                       for i in range(0, len(samples) - 2 * hop, hop)])
    level_db = 20 * np.log10(np.maximum(frames, 1e-9) / max(frames.max(), 1e-9))
    quiet = round(pause_s / HOP_S)
    loud = np.concatenate([np.zeros(quiet, bool), level_db > floor_db])
    return [(k - quiet) * HOP_S for k in range(quiet, len(loud)) if loud[k] and not loud[k - quiet:k].any()]


def pause_errors(clip, pause_s: float, floor_db: float) -> list[float]:
    """The engine's nearest onset minus each sound start after a pause (pairs within PAIR_S)."""
    onsets = np.array([w.start_s for w in clip.words])
    errors = []
    for start in pause_onsets(clip.audio_path, pause_s, floor_db):
        nearest = onsets[np.argmin(np.abs(onsets - start))] if len(onsets) else None
        if nearest is not None and abs(nearest - start) <= PAIR_S:
            errors.append(float(nearest - start))
    return errors


def summary(errors: list[float]) -> dict:
    if not errors:
        return {"words": 0}
    absolute = np.abs(errors) * 1000
    return {"words": len(errors), "median_abs_ms": round(float(np.median(absolute)), 1),
            "p90_abs_ms": round(float(np.percentile(absolute, 90)), 1),
            "p95_abs_ms": round(float(np.percentile(absolute, 95)), 1),
            "mean_signed_ms": round(float(np.mean(errors) * 1000), 1),
            "within_40ms": round(float(np.mean(absolute <= TARGET_MS)), 3)}


def measure(lines: list[str], pauses_s: list[float], floor_db: float) -> dict:
    folder = tempfile.mkdtemp(prefix="emopose-onsets-")
    piper, espeak = PiperSynthesizer(audio_dir=folder), EspeakSynthesizer(audio_dir=folder)
    asr = WhisperTranscriber()
    raw = {"piper": [], "espeak": []}
    corrected, pauses = [], {p: {"piper": [], "espeak": []} for p in pauses_s}
    for line in lines:
        clips = {"piper": piper.synthesize(line), "espeak": espeak.synthesize(line)}
        errors = {name: whisper_errors(clip, asr.transcribe_detail(clip.audio_path))
                  for name, clip in clips.items()}
        corrected += [error - errors["espeak"][char] for char, error in errors["piper"].items()
                      if char in errors["espeak"]]
        for (name, clip), pause_s in itertools.product(clips.items(), pauses_s):
            raw[name] += list(errors[name].values()) if pause_s == pauses_s[0] else []
            pauses[pause_s][name] += pause_errors(clip, pause_s, floor_db)
    return {"sentences": len(lines), "target_ms": TARGET_MS,
            "whisper_raw": {name: summary(e) for name, e in raw.items()},
            "piper_vs_whisper_corrected_by_espeak_per_word": summary(corrected),
            "after_pauses": {"floor_db": floor_db, **{f"{p}s": {n: summary(e) for n, e in engines.items()}
                                                      for p, engines in pauses.items()}}}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--limit", type=int, default=None)
    parser.add_argument("--pause-s", type=float, nargs="+", default=[0.05, 0.1])
    parser.add_argument("--floor-db", type=float, default=-35.0)
    args = parser.parse_args()
    lines = [s.strip() for s in SENTENCES.read_text().splitlines() if s.strip()][:args.limit]
    print(json.dumps(measure(lines, args.pause_s, args.floor_db), indent=2))


if __name__ == "__main__":
    main()
