"""The embedded local planner: cue rules and segmentation (fast), model quality and plans (slow)."""

from __future__ import annotations

import json
import shutil

import pytest

from emopose.config import PROJECT_ROOT
from emopose.library import MotionLibrary
from emopose.planners.base import PlanRequest
from emopose.planners.local import anchoring_phrase, intensity_from_cues
from emopose.planners.segment import segments
from emopose.stages.parse import parse_plan

TRAIN_FILES = [str(PROJECT_ROOT / "experiments/train/train.jsonl"),
               str(PROJECT_ROOT / "experiments/train/train_sequences.jsonl")]


def test_intensity_cues():
    assert intensity_from_cues("The exhibit opens at nine.") == 3
    assert intensity_from_cues("This is really, truly important!") == 5
    assert intensity_from_cues("Maybe we could perhaps try it.") == 1
    assert intensity_from_cues("STOP RIGHT THERE") == 4


def test_anchoring_phrase_prefers_class_cue_then_opening_words():
    assert anchoring_phrase("Well, welcome to the lab", "welcoming") == "welcome"
    assert anchoring_phrase("so the cabinet by the door holds it", "pointing") == "the cabinet by"


def test_segments_keep_spans_and_boundary_strength():
    text = "Welcome in, everyone! The robot arm is over there, and it is fragile."
    pieces = segments(text)
    assert [p.text for p in pieces] == ["Welcome in", "everyone!", "The robot arm is over there",
                                        "and it is fragile."]
    assert [p.strong_break_before for p in pieces] == [True, False, True, False]
    assert all(text[p.start:p.end] == p.text for p in pieces)


@pytest.fixture(scope="module")
def planner(tmp_path_factory):
    from emopose.planners.local import LocalPlanner

    folder = tmp_path_factory.mktemp("lib") / "g1"
    shutil.copytree(PROJECT_ROOT / "library/g1", folder)
    library = MotionLibrary.from_config(paths=[str(folder)], limits=str(folder / "limits.yaml"),
                                        write_dir=str(folder))
    return LocalPlanner(library, TRAIN_FILES)


@pytest.mark.slow
def test_quality_floor_on_held_out_training_slice(planner):
    from emopose.planners.local_model import load_training

    held_out = load_training(planner.train_files, planner.model.config.holdout_percent, held_out=True)
    assert len(held_out) > 150
    _, proba = planner.model.encode_and_classify([i.text for i in held_out])
    from emopose import CLASSES

    accuracy = sum(CLASSES[k] == i.label for k, i in zip(proba.argmax(1), held_out)) / len(held_out)
    assert accuracy >= 0.72, f"held-out accuracy {accuracy:.3f}"


@pytest.mark.slow
def test_ordered_plan_with_triggers_from_the_reply(planner):
    text = "Welcome in, everyone! Please don't touch the robot arm; it is still calibrating."
    plan = parse_plan(planner.plan(PlanRequest(text)).raw, text)
    assert plan.reply == text and plan.source == "model"
    assert [r.cls for r in plan.records][:2] == ["welcoming", "rejecting"]
    for record in plan.records:
        assert record.trigger and record.trigger in text
        assert planner.library.get(record.variant).cls == record.cls


@pytest.mark.slow
def test_new_variant_is_selectable_without_retraining(planner):
    utterance = "Hello and welcome, let me salute you like a sailor!"
    before = json.loads(planner.plan(PlanRequest(utterance)).raw)["gestures"][0]
    assert before["class"] == "welcoming"
    wave = planner.library.get("face_wave")
    planner.library.save({"name": "sailor_salute", "class": "welcoming", "keyframes": [list(k) for k in wave.q],
                          "description": "A crisp sailor's salute: right hand snaps to the brow, then down."})
    after = json.loads(planner.plan(PlanRequest(utterance)).raw)["gestures"][0]
    assert after["variant"] == "sailor_salute"
