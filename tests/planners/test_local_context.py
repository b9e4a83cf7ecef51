"""planner=local_context: the dialogue read with the utterance, a checked training config, quality."""

from __future__ import annotations

import json
import re

import pytest

from emopose.planners.base import PlanRequest
from tests.planners.local_helpers import configured_local_planner


@pytest.mark.parametrize("override, message", [
    ("planner.training.split_loss_weight=abc", "split_loss_weight\n  Input should be a valid number"),
    ("planner.training.seed=1.5", "seed\n  Input should be a valid integer"),
    ("planner.training.epochs=0", "epochs\n  Input should be greater than or equal to 1"),
    ("planner.training.trainable_layers=7", "trainable_layers\n  Input should be less than or equal to 6"),
    ("+planner.training.epochz=3", "epochz\n  Extra inputs are not permitted"),
    ("planner.temperature=0", "temperature must be positive"),
])
def test_a_wrong_override_is_a_config_error_before_any_training(tmp_path, override, message, compose):
    from emopose.build import ConfigError, make

    cfg = compose("planner=local_context", f"planner.cache_dir={tmp_path}", override)
    with pytest.raises(ConfigError, match=re.escape(message)):
        make(cfg.planner, "planner", library=make(cfg.library, "library"))
    assert not list(tmp_path.iterdir())  # nothing trained, nothing cached


@pytest.fixture(scope="module")
def planner(tmp_path_factory):
    return configured_local_planner(tmp_path_factory.mktemp("lib") / "g1", "planner=local_context")


@pytest.mark.slow
def test_an_elliptical_reply_is_read_in_its_dialogue(planner):
    asked = ({"role": "assistant", "content": "Would you mind if I opened the window a little?"},)

    def first_class(history: tuple) -> str:
        raw = planner.plan(PlanRequest("Not at all.", history=history)).raw
        return json.loads(raw)["gestures"][0]["class"]

    assert first_class(asked) == "agreeing"
    assert first_class(()) == "rejecting"  # read alone, the words refuse


@pytest.mark.slow
def test_quality_floor_on_held_out_training_slice(planner):
    from emopose.jobs.train_local import context_metrics, held_out_metrics
    from emopose.planners.local_data import load_examples

    held_out = load_examples(planner.train_files, planner.model.config.holdout_percent, held_out=True)
    utterances = [e for e in held_out if not e.history]
    metrics = held_out_metrics(planner, utterances, [planner.score(e.text) for e in utterances])
    metrics.update(context_metrics(planner, [e for e in held_out if e.history]))
    # Measured (seeded, `+experiment=train_local planner=local_context`): single top-1 84.9 %, sequence exact
    # 51.3 %, anchor recall 81.5 %, exact variant 38.7 %, dialogues 77.3 % with history, 67.8 % without.
    assert metrics["singles"] > 250 and metrics["sequences"] >= 200 and metrics["dialogues"] >= 150
    assert metrics["single_top1"] >= 0.82, metrics
    assert metrics["sequence_exact"] >= 0.48, metrics
    assert metrics["anchor_recall"] >= 0.78, metrics
    assert metrics["exact_variant"] >= 0.35, metrics
    assert metrics["context_with_history"] >= metrics["context_without"] + 0.07, metrics
