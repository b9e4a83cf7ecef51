"""New motions added to the library as files (a description, no training data) are picked, no retraining.

tests/planners/new_motions/ holds five motion files of five classes and five utterances written about
each; neither the motions nor the utterances appear in the training split.
"""

from __future__ import annotations

import json
import shutil
from collections import Counter
from pathlib import Path

import pytest
import yaml

from emopose.contract import LibraryEntry
from emopose.planners.base import PlanRequest
from emopose.planners.local.direction import added_ways, off_way
from emopose.planners.local.probes import probe_moves
from tests.planners.local_helpers import configured_local_planner

NEW = Path(__file__).parent / "new_motions"


@pytest.fixture(scope="module")
def planner(tmp_path_factory):
    return configured_local_planner(tmp_path_factory.mktemp("lib") / "g1")


def add_new_motions(planner) -> None:
    folder = planner.library.snapshot.files["shrug"].parent  # the fixture's writable copy
    for motion_file in NEW.glob("*.yaml"):
        shutil.copy(motion_file, folder)
    planner.library.reload()


# Measured: picked for 5/5/4/5/5 of the utterances (sailor_salute, thumbs_up, finger_wag, head_scratch,
# point_down); the target is >= 4 of 5 each. The finger_wag miss is a class error (a scolded
# kitten read as comforting); without the pretrained share of the variant score palm_stop also took
# "No, no, no, Milo, bad dog" (5/5/3/5/5), and so it does with the seed-1 model.
# Earlier models: 5/5/2/5/5 without the shared-word term, 2/2/1/0/4 by the utterance-only planner.
# The floors leave a pick for training on another CPU.
@pytest.mark.slow
def test_each_new_motion_is_picked_for_the_utterances_about_it(planner):
    rows = [json.loads(line) for line in (NEW / "utterances.jsonl").read_text().splitlines()]
    add_new_motions(planner)
    assert {r["motion"] for r in rows} <= set(planner.library.snapshot.entries)
    picked: Counter = Counter()
    for row in rows:
        gestures = json.loads(planner.plan(PlanRequest(row["text"])).raw)["gestures"]
        picked[row["motion"]] += any(g["variant"] == row["motion"] for g in gestures[:1])
    per_motion = {m: picked[m] / sum(r["motion"] == m for r in rows) for m in {r["motion"] for r in rows}}
    assert min(per_motion.values()) >= 0.6 and sum(picked.values()) >= 0.88 * len(rows), per_motion


# Measured on the held-out slice: singles 87.8 -> 87.8 %, sequences exact 65.4 -> 64.5 % once the five are
# in the library (a new motion's fit may move an act's class further than a known one's:
# variant_class_weight_new; conf/planner/local.yaml has the cost with more motions added).
@pytest.mark.slow
def test_new_motions_cost_the_reading_of_other_utterances_little(tmp_path):
    from emopose.jobs.train_local import held_out_examples, held_out_metrics

    planner = configured_local_planner(tmp_path / "g1")
    examples = [e for e in held_out_examples(planner) if not e.history]
    scored = [planner.score(e.text) for e in examples]
    before = held_out_metrics(planner, examples, scored)
    add_new_motions(planner)
    after = held_out_metrics(planner, examples, scored)
    assert after["single_top1"] >= before["single_top1"] - 0.02, (before, after)
    assert after["sequence_exact"] >= before["sequence_exact"] - 0.02, (before, after)


MAPPING = {"left": "point_left", "up": "point_up", "down": "point_forward_right",
           "there": "point_forward_right"}


def test_an_added_pointing_motion_points_the_way_its_description_names():
    evidence = {"point_down": ("pointing", ("point down: Right arm points straight down at the floor",)),
                "point_with_flair": ("pointing", ("point with flair: a showy flourish of the hand",)),
                "point_up": ("pointing", ("point up: Right arm rises to point straight up",)),
                "finger_wag": ("rejecting", ("finger wag: wagged side to side, down low",))}
    ways = added_ways(evidence, MAPPING)
    assert ways == {"point_down": "down"}  # mapped, naming no way, or not pointing: the choice alone decides
    assert off_way("Mind the step down here at your feet.", ways) == frozenset()
    assert off_way("Tickets are sold at the main entrance.", ways) == {"point_down"}  # names no way
    assert off_way("Check the board above the platform.", ways) == {"point_down"}  # names another


# Before the rule (direction.py's off_way), point_down took the neutral probe "Tickets are sold at the main
# entrance." (read as pointing by the class head, as the training data reads a place named for the
# listener) from point_forward_right, and "Check the board above the platform ..." (held-out) from point_up,
# on place words that sound like its "floor" and "ground".
@pytest.mark.slow
def test_an_added_pointing_motion_takes_only_acts_that_name_its_way(planner):
    point_down = LibraryEntry.model_validate(yaml.safe_load((NEW / "point_down.yaml").read_text()))
    assert not [m for m in probe_moves(planner, point_down) if m.intent != "pointing"]
    add_new_motions(planner)
    plan = planner.plan(PlanRequest("Check the board above the platform for the next train."))
    assert [g["variant"] for g in json.loads(plan.raw)["gestures"]] == ["point_up"]
