"""asr=whisper over a listening test (#32): word error rate and real-time factor of tiny.en.

The test set is made here, not committed: every sentence of benchmarks/data/listen/sentences.txt
(original, written for this test) is spoken by a voice that is not the one being tested, into
<out>/NN.wav with the sentence as <out>/NN.txt:
  --voice piper (default): the packaged piper voice (joe-us, one speaker, so variety comes from its
      settings), cycling length_scale 0.85-1.2 (pace), noise_scale and noise_w (its sampling noise: how
      each render varies; unseeded, so a rerun hears slightly different audio), with 0.3 s of silence
      around the speech as in a recording, resampled from 22.05 to 16 kHz mono; every tenth file (from
      the 4th) is 8 kHz mono and every tenth (from the 8th) 16 kHz stereo, to exercise the conversion;
  --voice espeak: the espeak-ng command line with voices other than the robot's own (en-us at 165 wpm),
      cycling through accents, male/female variants and rates 130-190 wpm (22.05 kHz mono files).
Then the listen job's folder mode (emopose.jobs.listen.transcribe_folder) transcribes them with the
packaged tiny.en, int8, 2 threads, after one warm-up file (the first decode also builds CTranslate2's
kernels). The summary gives the load average too: wall times on the shared 2-core machine depend on
it, so it also gives the process's CPU seconds per audio second (`cpu_per_audio_s`), which load barely
changes: on an idle machine the real-time factor is at most that (one core busy), about half with two.
Targets (issue 32): WER <= 10 %, real-time factor <= 0.3 on the 2-core machine.
Run: python benchmarks/asr_wer.py [--voice piper|espeak] [--out DIR] [--limit N]
     -> JSON summary on stdout, items in DIR.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import tempfile
import time
import wave
from pathlib import Path

import numpy as np
from scipy.signal import resample_poly

from emopose.jobs.listen import transcribe_folder
from emopose.speech.whisper_asr import WhisperTranscriber

SENTENCES = Path(__file__).parent / "data" / "listen" / "sentences.txt"
ESPEAK_VOICES = ["en-gb", "en-gb-scotland", "en-gb-x-rp", "en-gb-x-gbclan", "en-gb-x-gbcwmd", "en-029",
                 "en-us-nyc", "en-us+f3", "en-gb+f2", "en-us+m3", "en-gb+m5"]
ESPEAK_RATES = [130, 150, 170, 190]
PIPER_LENGTH_SCALES = [0.85, 1.0, 1.1, 1.2, 0.92]   # > 1 is slower; co-prime cycle lengths so the
PIPER_NOISE = [(0.667, 0.8), (0.4, 0.5), (0.9, 1.0)]  # (noise_scale, noise_w) combinations vary
PAD_S = 0.3


def sentences(limit: int | None) -> list[str]:
    return [s.strip() for s in SENTENCES.read_text().splitlines() if s.strip()][:limit]


def make_espeak_set(out: Path, limit: int | None) -> list[dict]:
    made = []
    for k, sentence in enumerate(sentences(limit)):
        voice = ESPEAK_VOICES[k % len(ESPEAK_VOICES)]
        rate = ESPEAK_RATES[(k // len(ESPEAK_VOICES) + k) % len(ESPEAK_RATES)]
        wav = out / f"{k:02d}.wav"
        subprocess.run(["espeak-ng", "-v", voice, "-s", str(rate), "-w", str(wav), sentence], check=True)
        wav.with_suffix(".txt").write_text(sentence + "\n")
        made.append({"file": wav.name, "voice": voice, "rate": rate})
    return made


def file_format(k: int) -> tuple[int, int]:
    """(sample rate, channels) of the k-th file: mostly 16 kHz mono, a few 8 kHz and stereo."""
    return {3: (8000, 1), 7: (16000, 2)}.get(k % 10, (16000, 1))


def make_piper_set(out: Path, limit: int | None) -> list[dict]:
    from piper import SynthesisConfig

    from emopose.speech.piper_tts import load_voice

    voice = load_voice()
    source_rate = int(voice.config.sample_rate)
    made = []
    for k, sentence in enumerate(sentences(limit)):
        length_scale = PIPER_LENGTH_SCALES[k % len(PIPER_LENGTH_SCALES)]
        noise_scale, noise_w = PIPER_NOISE[k % len(PIPER_NOISE)]
        config = SynthesisConfig(length_scale=length_scale, noise_scale=noise_scale, noise_w_scale=noise_w)
        speech = np.concatenate([c.audio_int16_array for c in voice.synthesize(sentence, syn_config=config)])
        pad = np.zeros(int(PAD_S * source_rate), dtype=np.int16)
        rate, channels = file_format(k)
        wav = out / f"{k:02d}.wav"
        write_wav(wav, np.concatenate([pad, speech, pad]), source_rate, rate, channels)
        wav.with_suffix(".txt").write_text(sentence + "\n")
        made.append({"file": wav.name, "voice": "piper joe-us", "length_scale": length_scale,
                     "noise_scale": noise_scale, "noise_w": noise_w, "sample_rate": rate,
                     "channels": channels})
    return made


def write_wav(path: Path, samples: np.ndarray, source_rate: int, rate: int, channels: int) -> None:
    """16-bit WAV at `rate` (polyphase resampling, anti-aliased); stereo repeats the channel."""
    divisor = np.gcd(rate, source_rate)
    resampled = resample_poly(samples.astype(np.float64), rate // divisor, source_rate // divisor)
    pcm = np.clip(np.round(resampled), -32768, 32767).astype("<i2")
    with wave.open(str(path), "wb") as audio:
        audio.setnchannels(channels)
        audio.setsampwidth(2)
        audio.setframerate(rate)
        audio.writeframes(np.repeat(pcm, channels).tobytes())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--voice", choices=["piper", "espeak"], default="piper")
    parser.add_argument("--out", type=Path, default=None)
    parser.add_argument("--limit", type=int, default=None)
    args = parser.parse_args()
    out = args.out or Path(tempfile.mkdtemp(prefix=f"emopose-listen-{args.voice}-"))
    out.mkdir(parents=True, exist_ok=True)
    made = (make_piper_set if args.voice == "piper" else make_espeak_set)(out, args.limit)
    asr = WhisperTranscriber()
    asr.transcribe_detail(out / made[0]["file"])  # warm-up, not counted
    load_before, cpu_before = os.getloadavg()[0], time.process_time()
    results, markdown = transcribe_folder(asr, out)
    cpu_s = time.process_time() - cpu_before
    (out / "results.json").write_text(json.dumps({**results, "voices": made}, indent=2))
    (out / "results.md").write_text(markdown + "\n")
    wrong = [{k: i.get(k) for k in ("file", "reference", "transcript", "wer")} for i in results["items"]
             if i.get("wer")]
    print(json.dumps({"folder": str(out), "voice": args.voice, "sentences": len(made),
                      "wer": results["wer"], "reference_words": results["reference_words"],
                      "real_time_factor": results["real_time_factor"], "audio_s": results["audio_s"],
                      "cpu_per_audio_s": cpu_s / results["audio_s"] if results["audio_s"] else None,
                      "load_average_1min": [load_before, os.getloadavg()[0]],
                      "failed": results["failed"], "with_errors": wrong}, indent=2))


if __name__ == "__main__":
    main()
