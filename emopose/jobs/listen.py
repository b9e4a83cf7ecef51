"""+experiment=listen: speech in -> transcript (with word timestamps) -> the turn, or WER over a folder.

  audio=PATH         transcribe the file, run the turn on the transcript (planner, speech, gestures) and
                     write transcript, words, asr_ms, the turn and its stage timings;
  job.audio_dir=DIR  transcribe every *.wav in DIR (sorted by name); an item's reference is the text of
                     the .txt file with the same stem, where present; results hold each item's WER and
                     the overall WER (errors summed over all reference words) and real-time factor.
A file that cannot be transcribed becomes an item with its `error` (a folder run goes on); a silent file
is an item with an empty transcript and the warning "no speech detected" (WER 1 against a reference).
For audio=PATH, a file that gives no transcript (missing, not audio, longer than asr.max_duration_s, only
silence or noise) and a bad job setting end the run with one line (ConfigError: exit 2, no traceback).
  audio=PATH job.barge_in_at_s=S job.barge_in_audio=PATH2
                     the visitor interrupts the reply S seconds into its audio with a second recording:
                     barge-in latency, the second turn, VAD end -> first audio (listen_barge_in.py).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from emopose.build import ConfigError
from emopose.jobs.listen_barge_in import barge_in_turns
from emopose.resources import Run
from emopose.results import JobOutput, markdown_table
from emopose.speech.asr import ASRError
from emopose.speech.wer import word_errors
from emopose.speech.whisper_asr import Transcript, WhisperTranscriber


@dataclass
class ListenJob:
    audio: str | None = None
    audio_dir: str | None = None
    barge_in_at_s: float | None = None  # with barge_in_audio: the visitor interrupts the reply
    barge_in_audio: str | None = None
    echo_gain: float = 0.25             # the robot's reply at its microphone: -12 dB

    def __call__(self, run: Run) -> JobOutput:
        asr = run.resources.asr
        if not isinstance(asr, WhisperTranscriber):
            name = getattr(asr, "name", "none")
            raise ConfigError(f"listen needs word timestamps from asr=whisper, but asr is {name!r}")
        if (self.audio is None) == (self.audio_dir is None):
            raise ConfigError("listen takes one of audio=PATH.wav or job.audio_dir=DIR")
        if (self.barge_in_at_s is None) != (self.barge_in_audio is None) or (
                self.barge_in_at_s is not None and (self.audio is None or self.barge_in_at_s < 0)):
            raise ConfigError("a barge-in takes audio=PATH.wav, job.barge_in_at_s >= 0 (seconds into the "
                              "reply's audio) and job.barge_in_audio=PATH.wav (the visitor's 2nd recording)")
        if self.audio_dir:
            return transcribe_folder(asr, Path(self.audio_dir))
        try:
            return self._one(run, asr, Path(self.audio))
        except ASRError as exc:  # the run's input gave no transcript: its one line names the file
            raise ConfigError(f"listen: {exc}") from exc

    def _one(self, run: Run, asr: WhisperTranscriber, path: Path) -> JobOutput:
        heard = asr.transcribe_detail(path)
        if not heard.text:
            raise ASRError(f"{path.name}: no speech recognised ({'; '.join(heard.warnings) or 'empty'})")
        if self.barge_in_at_s is not None:
            return self._barge_in(run, asr, path, heard)
        turn = run.runner.run(heard.text)
        data = turn.to_json()
        results = {"file": str(path), **_heard(heard), "reply": turn.plan.reply,
                   "planner": run.resources.planner.name, "speech_duration_s": turn.speech.duration_s,
                   "stage_ms": data["stage_ms"], "turn": data}
        text = (f"Heard ({heard.duration_s:.1f} s of audio, {heard.asr_s * 1000:.0f} ms): {heard.text}\n"
                f"Reply: {turn.plan.reply}\nStage ms: {data['stage_ms']}")
        return results, text

    def _barge_in(self, run: Run, asr: WhisperTranscriber, path: Path, heard: Transcript) -> JobOutput:
        found = barge_in_turns(run, asr, heard.text, Path(self.barge_in_audio), self.barge_in_at_s,
                               self.echo_gain)
        results = {"file": str(path), **_heard(heard), "planner": run.resources.planner.name, **found}
        stops = found["barge_ins"]
        text = (f"Heard: {heard.text}\nReply: {found['reply']}\n"
                + (f"Barge-in: the robot stopped {stops[0]['stopped_after_voice_ms']:.0f} ms after the "
                   "visitor's voice began" if stops else "No barge-in detected")
                + (f"\nSecond turn: {found['second']['transcript']} -> {found['second'].get('reply')}"
                   if "second" in found else ""))
        return results, text


def transcribe_folder(asr: WhisperTranscriber, folder: Path) -> JobOutput:
    """Every *.wav of `folder` transcribed and scored against its same-stem .txt (the folder mode)."""
    files = sorted(folder.glob("*.wav")) if folder.is_dir() else []
    if not files:
        raise ConfigError(f"job.audio_dir {folder} holds no .wav files")
    items, errors, words, audio_s, asr_s = [], 0, 0, 0.0, 0.0
    for path in files:
        reference_file = path.with_suffix(".txt")
        reference = reference_file.read_text().strip() if reference_file.is_file() else None
        try:
            heard = asr.transcribe_detail(path)
        except ASRError as exc:
            items.append({"file": path.name, "reference": reference, "error": str(exc)})
            continue
        item = {"file": path.name, **_heard(heard), "reference": reference, "wer": None}
        if reference is not None:
            wrong, count = word_errors(reference, heard.text)
            item["wer"], errors, words = (wrong / count if count else None), errors + wrong, words + count
        audio_s, asr_s = audio_s + heard.duration_s, asr_s + heard.asr_s
        items.append(item)
    results = {"audio_dir": str(folder), "items": items, "wer": errors / words if words else None,
               "reference_words": words, "audio_s": audio_s, "asr_s": asr_s,
               "real_time_factor": asr_s / audio_s if audio_s else None,
               "failed": sum("error" in i for i in items)}
    rows = [[i["file"], i.get("transcript", i.get("error", "")),
             "-" if i.get("wer") is None else f"{i['wer']:.0%}"] for i in items]
    summary = (f"WER {results['wer']:.1%} over {words} reference words; " if words else "No references; ")
    summary += f"real-time factor {results['real_time_factor'] or 0:.2f}; {results['failed']} failed"
    return results, markdown_table(["file", "transcript", "WER"], rows) + "\n\n" + summary


def _heard(heard: Transcript) -> dict:
    return {"transcript": heard.text, "asr_ms": heard.asr_s * 1000, "duration_s": heard.duration_s,
            "real_time_factor": heard.real_time_factor, "warnings": heard.warnings,
            "words": [[w.text, round(w.start_s, 3), round(w.end_s, 3)] for w in heard.words]}
