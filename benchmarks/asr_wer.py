"""asr=whisper over a listening test (#32): word error rate and real-time factor of tiny.en.

The test set is made here, not committed: every sentence of benchmarks/data/listen/sentences.txt
(original, written for this test) is spoken by the espeak-ng command line with a voice other than the
robot's own (en-us at 165 wpm), cycling through accents, male/female variants and rates 130-190 wpm,
into <out>/NN.wav with the sentence as <out>/NN.txt. Then the listen job's folder mode
(emopose.jobs.listen.transcribe_folder) transcribes them with the packaged tiny.en, int8, 2 threads,
after one warm-up file (the first decode also builds CTranslate2's kernels).
Targets (issue 32): WER <= 10 %, real-time factor <= 0.3 on the 2-core machine.
Run: python benchmarks/asr_wer.py [--out DIR] [--limit N] -> JSON summary on stdout, items in DIR.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import tempfile
from pathlib import Path

from emopose.jobs.listen import transcribe_folder
from emopose.speech.whisper_asr import WhisperTranscriber

SENTENCES = Path(__file__).parent / "data" / "listen" / "sentences.txt"
VOICES = ["en-gb", "en-gb-scotland", "en-gb-x-rp", "en-gb-x-gbclan", "en-gb-x-gbcwmd", "en-029",
          "en-us-nyc", "en-us+f3", "en-gb+f2", "en-us+m3", "en-gb+m5"]
RATES = [130, 150, 170, 190]


def make_test_set(out: Path, limit: int | None) -> list[dict]:
    out.mkdir(parents=True, exist_ok=True)
    lines = [s.strip() for s in SENTENCES.read_text().splitlines() if s.strip()][:limit]
    made = []
    for k, sentence in enumerate(lines):
        voice, rate = VOICES[k % len(VOICES)], RATES[(k // len(VOICES) + k) % len(RATES)]
        wav = out / f"{k:02d}.wav"
        subprocess.run(["espeak-ng", "-v", voice, "-s", str(rate), "-w", str(wav), sentence], check=True)
        wav.with_suffix(".txt").write_text(sentence + "\n")
        made.append({"file": wav.name, "voice": voice, "rate": rate})
    return made


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=None)
    parser.add_argument("--limit", type=int, default=None)
    args = parser.parse_args()
    out = args.out or Path(tempfile.mkdtemp(prefix="emopose-listen-"))
    made = make_test_set(out, args.limit)
    asr = WhisperTranscriber()
    asr.transcribe_detail(out / made[0]["file"])  # warm-up, not counted
    results, markdown = transcribe_folder(asr, out)
    (out / "results.json").write_text(json.dumps({**results, "voices": made}, indent=2))
    (out / "results.md").write_text(markdown + "\n")
    wrong = [{k: i.get(k) for k in ("file", "reference", "transcript", "wer")} for i in results["items"]
             if i.get("wer")]
    print(json.dumps({"folder": str(out), "sentences": len(made), "voices": len({m["voice"] for m in made}),
                      "wer": results["wer"], "reference_words": results["reference_words"],
                      "real_time_factor": results["real_time_factor"], "audio_s": results["audio_s"],
                      "failed": results["failed"], "with_errors": wrong}, indent=2))


if __name__ == "__main__":
    main()
