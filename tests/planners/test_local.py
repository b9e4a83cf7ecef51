"""The embedded local planner: cue rules and segmentation (fast), model quality and plans (slow)."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from emopose.planners.base import PlanRequest
from emopose.planners.local.affiliate import trigger_span
from emopose.planners.local.data import multi_act, single_act, synthetic_sequences
from emopose.planners.local.heads import Analysis
from emopose.planners.local.planner import intensity_from_cues
from emopose.planners.local.segment import segments
from emopose.stages.parse import parse_plan
from tests.planners.local_helpers import configured_local_planner


def test_intensity_cues():
    assert intensity_from_cues("The exhibit opens at nine.") == 3
    assert intensity_from_cues("This is really, truly important!") == 5
    assert intensity_from_cues("Maybe we could perhaps try it.") == 1
    assert intensity_from_cues("STOP RIGHT THERE") == 4


def test_multi_act_items_assign_every_segment_to_an_annotated_act():
    example = multi_act({"id": "x", "text": "Oh hello, come in! The coats go over there, on the left hooks.",
                         "labels": ["welcoming", "pointing"], "anchors": ["come in", "over there"],
                         "variants": ["beckon_in", "point_left"]})
    assert [(example.text[a.start:a.end], a.label) for a in example.acts] == [
        ("Oh hello, come in!", "welcoming"), ("The coats go over there, on the left hooks.", "pointing")]
    assert example.boundaries == [0, 1, 0]
    assert [example.text[a:b] for a, b in example.anchors] == ["come in", "over there"]
    shared = {"id": "y", "text": "Yes over there.", "labels": ["agreeing", "pointing"],
              "anchors": ["Yes", "over there"], "variants": ["double_hand_nod", "point_left"]}
    assert multi_act(shared) is None  # two anchors in one segment: no usable act boundary


def test_synthetic_sequences_join_items_of_different_classes():
    singles = [single_act(f"s{k}", text, label) for k, (text, label) in enumerate([
        ("Welcome aboard, everyone.", "welcoming"), ("The lifejackets are under your seat.", "pointing"),
        ("Please don't lean over the rail!", "rejecting"),
        ("I'm not convinced the fog will lift.", "doubting")])]
    joined = synthetic_sequences(singles, 40, seed=3)
    assert len(joined) >= 30
    for example in joined:
        labels = [a.label for a in example.acts]
        assert 2 <= len(labels) <= 4 and all(a != b for a, b in zip(labels, labels[1:]))
        assert sum(example.boundaries) == len(labels) - 1
        assert all(example.text[a.start:a.end].strip() for a in example.acts)
    assert len({e.text for e in joined}) > 20


def word_analysis(text: str, onset_word: str, marked: tuple[str, ...] = (), peak: str | None = None,
                  occurrence: int = 0) -> Analysis:
    """One token per word: the onset head peaks on the given occurrence of onset_word, the anchor head
    marks the `marked` words and is strongest on `peak` (default: the onset word)."""
    found = list(re.finditer(r"[\w']+", text))
    words, starts = [m.group() for m in found], [m.start() for m in found]
    at = lambda word: [k for k, w in enumerate(words) if w == word][occurrence]  # noqa: E731
    onset = np.full(len(words), -3.0)
    onset[at(onset_word)] = 2.0
    anchor = np.array([1.0 if w in marked else -1.0 for w in words])
    anchor[at(peak or onset_word)] = 2.0
    return Analysis(starts, None, None, None, anchor, onset)


def test_trigger_starts_at_the_onset_word_and_runs_to_the_end_of_the_marked_phrase():
    text = "Thanks for coming, the cloakroom is downstairs on the left."
    act = (19, len(text) - 1)
    analysis = word_analysis(text, "downstairs", ("cloakroom", "is", "on", "the", "left"))
    assert text[slice(*trigger_span(text, analysis, act))] == "downstairs on the left"  # not "cloakroom is"
    analysis = word_analysis(text, "downstairs", ("the", "left"))  # a gap after the onset word ends it
    assert text[slice(*trigger_span(text, analysis, act))] == "downstairs"
    analysis = word_analysis(text, "the", tuple(re.findall(r"\w+", text)))
    span = trigger_span(text, analysis, act, max_words=3)  # everything marked: capped
    assert text[slice(*span)] == "the cloakroom is" and act[0] <= span[0] and span[1] <= act[1]


def test_the_onset_is_never_after_the_phrases_strongest_word():
    text = "Thanks for coming, the cloakroom is downstairs on the left."
    analysis = word_analysis(text, "left", ("is",), peak="cloakroom")
    assert text[slice(*trigger_span(text, analysis, (19, len(text) - 1)))] == "the cloakroom is"


def test_a_trigger_is_extended_until_the_reply_has_it_nowhere_earlier():
    text = "The lamp by the window is new, and the one by the door is old."
    act = (text.index("and"), len(text) - 1)
    analysis = word_analysis(text, "by", (), occurrence=1)  # "by" and "by the" occur earlier
    assert text[slice(*trigger_span(text, analysis, act))] == "by the door"


def test_an_onset_on_punctuation_gives_the_word_before_it():
    text = "Thanks for coming, the cloakroom is downstairs on the left."
    analysis = word_analysis(text, "left")
    analysis.starts.append(len(text) - 1)  # the final full stop is a token of its own, both heads' peak
    analysis.onset_logits = np.append(np.full(len(analysis.anchor_logits), -3.0), 5.0)
    analysis.anchor_logits = np.append(np.full(len(analysis.anchor_logits), -1.0), 3.0)
    assert text[slice(*trigger_span(text, analysis, (0, len(text))))] == "left"


def test_train_local_search_is_checked_before_anything_is_built():
    from emopose.jobs.train_local import TrainLocalJob

    assert TrainLocalJob(search={"act_cost": [-1.0, -0.5], "temperature": [2, 3]}, retrain=False).search
    with pytest.raises(ValueError, match="unknown split parameters"):
        TrainLocalJob(search={"epochs": [3]}, retrain=False)
    with pytest.raises(ValueError, match="list of numbers"):
        TrainLocalJob(search={"act_cost": -1.0}, retrain=False)


@pytest.mark.parametrize("override, message", [  # validated by pydantic (planners/local/config.py)
    ("planner.training.split_loss_weight=abc", "split_loss_weight\n  Input should be a valid number"),
    ("planner.training.seed=1.5", "seed\n  Input should be a valid integer"),
    ("planner.training.epochs=0", "epochs\n  Input should be greater than or equal to 1"),
    ("planner.training.lr=-0.1", "lr\n  Input should be greater than or equal to 0"),
    ("planner.training.trainable_layers=7", "trainable_layers\n  Input should be less than or equal to 6"),
    ("planner.training.dropout=1", "dropout\n  Input should be less than 1"),
    ("+planner.training.epochz=3", "epochz\n  Extra inputs are not permitted"),
    ("~planner.training.epochs", "epochs\n  Field required"),  # the YAML is the one place of every value
    ("~planner.history_threshold", "history_threshold\n  Field required"),
    ("+planner.temprature=2", "temprature\n  Extra inputs are not permitted"),
    ("planner.temperature=0", "temperature\n  Input should be greater than 0"),
    ("planner.variant_class_weight=-1", "variant_class_weight\n  Input should be greater than or equal"),
    ("planner.variant_class_weight_new=inf", "variant_class_weight_new\n  Input should be a finite number"),
    ("planner.variant_shared_weight=-0.5", "variant_shared_weight\n  Input should be greater than"),
    ("planner.variant_pretrained_share=1.5", "variant_pretrained_share\n  Input should be less than"),
    ("planner.history_threshold=null", "history_threshold\n  Input should be a valid number"),
    ("planner.history_threshold=nan", "history_threshold\n  Value error, must be a number"),
    ("~planner.train_if_missing", "missing 1 required keyword-only argument: 'train_if_missing'"),
])
def test_a_wrong_planner_override_is_a_config_error_before_any_training(tmp_path, override, message, compose):
    from emopose.build import ConfigError, make

    cfg = compose("planner=local", f"planner.cache_dir={tmp_path}", override)
    with pytest.raises(ConfigError, match=re.escape(message)):
        make(cfg.planner, "planner", library=make(cfg.library, "library"))
    assert not list(tmp_path.iterdir())  # nothing trained, nothing cached


@pytest.mark.parametrize("train_if_missing", [True, False])
def test_training_runs_only_as_the_named_first_use_step(tmp_path, compose, monkeypatch, train_if_missing):
    """No cached artifact: train_if_missing trains before the planner is built (its __init__ only loads);
    without it, building fails naming the job that trains and the setting."""
    from emopose.build import ConfigError, make
    from emopose.planners.local import artifact

    class Trained(Exception):
        pass

    def train_artifact(paths, cache_dir, config, catalogue):
        assert cache_dir == str(tmp_path) and "face_wave" in catalogue
        raise Trained  # a stand-in for minutes of training

    monkeypatch.setattr(artifact, "train_artifact", train_artifact)
    cfg = compose("planner=local", f"planner.cache_dir={tmp_path}",
                  f"planner.train_if_missing={train_if_missing}")
    library = make(cfg.library, "library")
    if train_if_missing:
        with pytest.raises(Trained):
            make(cfg.planner, "planner", library=library)
    else:
        with pytest.raises(ConfigError, match=r"no trained local planner at .*python -m emopose "
                                              r"\+experiment=train_local.*planner\.train_if_missing=true"):
            make(cfg.planner, "planner", library=library)


def test_the_yaml_sets_every_setting_and_trains_on_first_use_by_default(compose):
    from omegaconf import OmegaConf

    from emopose.planners.local.config import LocalSettings

    planner = OmegaConf.to_container(compose("planner=local").planner, resolve=True)
    assert planner.pop("_target_") == "emopose.planners.local.planner.LocalPlanner.from_config"
    assert planner.pop("train_if_missing") is True  # the README's main job trains on a fresh machine
    assert LocalSettings.model_validate(planner).training.holdout_percent == 10


def test_segments_keep_spans_and_boundary_strength():
    text = "Welcome in, everyone! The robot arm is over there, and it is fragile."
    pieces = segments(text)
    assert [p.text for p in pieces] == ["Welcome in", "everyone!", "The robot arm is over there",
                                        "and it is fragile."]
    assert [p.strong_break_before for p in pieces] == [True, False, True, False]
    assert all(text[p.start:p.end] == p.text for p in pieces)


@pytest.fixture(scope="module")
def planner(tmp_path_factory):
    return configured_local_planner(tmp_path_factory.mktemp("lib") / "g1")


@pytest.mark.slow
def test_quality_floor_on_held_out_training_slice(planner):
    from emopose.jobs.train_local import (
        context_metrics,
        held_out_examples,
        held_out_metrics,
        scored_dialogues,
    )

    held_out = held_out_examples(planner)
    utterances = [e for e in held_out if not e.history]
    metrics = held_out_metrics(planner, utterances, [planner.score(e.text) for e in utterances])
    dialogues = [e for e in held_out if e.history]
    metrics.update(context_metrics(planner, dialogues, scored_dialogues(planner, dialogues)))
    # Measured (seeded, `+experiment=train_local`): single top-1 86.3 %, sequence exact 63.2 %, anchor
    # recall 86.4 %, exact variant 50.6 %, dialogues 87.7 % with history, 78.2 % without. Floors leave
    # about 3 points for training on another CPU (bfloat16 support and thread counts change the sums);
    # the history must still add at least five points (a plain answer needs no history to read neutral).
    assert metrics["singles"] > 250 and metrics["sequences"] >= 200 and metrics["dialogues"] >= 150
    assert metrics["single_top1"] >= 0.84, metrics
    assert metrics["sequence_exact"] >= 0.58, metrics
    assert metrics["anchor_recall"] >= 0.81, metrics
    assert metrics["exact_variant"] >= 0.49, metrics
    assert metrics["context_with_history"] >= 0.83, metrics
    assert metrics["context_with_history"] >= metrics["context_without"] + 0.05, metrics


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
def test_the_loaded_planner_keeps_the_planner_contract(planner):
    from emopose.planners.base import ModalPlanner, Planner
    from emopose.planners.local.planner import LocalPlanner

    assert isinstance(planner, LocalPlanner) and isinstance(planner, Planner) and not planner.sampled
    assert not isinstance(planner, ModalPlanner)  # it always narrates: the reply is the utterance


@pytest.mark.slow
def test_blank_utterance_gets_a_plan_without_gestures(planner):
    for text in ("", "   \n", "\u200b"):  # a zero-width space alone has no token either
        assert json.loads(planner.plan(PlanRequest(text)).raw) == {"reply": text, "gestures": []}


@pytest.mark.slow
def test_new_variant_is_selectable_without_retraining(planner):
    # An act about the new motion picks it (tests/planners/test_local_new_motions.py: five motions).
    utterance = "Welcome aboard, let me give you a proper sailor's salute!"
    before = json.loads(planner.plan(PlanRequest(utterance)).raw)["gestures"][0]
    assert before["class"] == "welcoming"
    wave = planner.library.get("face_wave")
    planner.library.save({"name": "sailor_salute", "class": "welcoming",
                          "keyframes": [list(k) for k in wave.q],
                          "description": "A crisp sailor's salute: right hand snaps to the brow, then down."})
    after = json.loads(planner.plan(PlanRequest(utterance)).raw)["gestures"][0]
    assert after["variant"] == "sailor_salute"
