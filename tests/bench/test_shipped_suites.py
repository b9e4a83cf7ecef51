"""The shipped suite files: counts, balance, fields, anchor order and variants."""

import json
from collections import Counter
from itertools import pairwise
from pathlib import Path

from emopose import CLASSES
from emopose.bench.suites import TIERS, load_bench, load_context, load_sequence
from emopose.config import PROJECT_ROOT

BENCH = PROJECT_ROOT / "experiments/bench/emopose_bench.jsonl"
CONTEXT = PROJECT_ROOT / "experiments/context/context_suite.jsonl"
SEQUENCE = PROJECT_ROOT / "experiments/sequence/sequence_suite.jsonl"

# The spec's motion names by class: class membership is checked against this even without the library.
SPEC_MOTIONS = {
    "pointing": ("point_forward_right", "point_left", "point_up", "point_to_self"),
    "emphasizing": ("beat_both_hands", "chop_right", "palms_down_press", "raised_fist_emphasis"),
    "rejecting": ("palm_stop", "cross_arms_x", "wave_off", "push_away"),
    "agreeing": ("affirm_palm_forward", "double_hand_nod", "raise_arm_yes"),
    "doubting": ("shrug", "chin_stroke", "palm_tilt_waver"),
    "welcoming": ("face_wave", "open_arms", "beckon_in", "sweep_invite"),
    "comforting": ("hands_on_heart", "gentle_pat", "calm_down_palms", "reach_out_support", "self_hug"),
    "neutral": ("idle_breathe", "hands_clasped", "neutral_rest", "neutral_ready"),
}


def need(path: Path) -> Path:
    assert path.is_file(), f"{path.relative_to(PROJECT_ROOT)} is missing: the suites ship with the repository"
    return path


def test_bench_counts():
    items = load_bench(need(BENCH))
    assert len(items) == 480
    cells = Counter((i.tier, i.label) for i in items)
    assert set(cells) == {(t, c) for t in TIERS for c in CLASSES}
    assert set(cells.values()) == {20}, {k: v for k, v in cells.items() if v != 20}


def test_context_counts():
    items = load_context(need(CONTEXT))
    assert len(items) == 320
    assert Counter(i.label for i in items) == {c: 40 for c in CLASSES}


def test_sequence_counts_and_positions():
    items = load_sequence(need(SEQUENCE))
    assert len(items) == 320
    assert Counter(len(i.labels) for i in items) == {2: 80, 3: 160, 4: 80}
    assert sum(len(i.labels) for i in items) == 960  # annotated action positions per pass (paper)
    for item in items:
        spans = item.spans  # anchors are exact substrings, left to right
        assert all(a[1] <= b[0] for a, b in pairwise(spans)), item.id


def test_sequence_variants_belong_to_their_class():
    spec = {name: cls for cls, names in SPEC_MOTIONS.items() for name in names}
    load_sequence(need(SEQUENCE), variant_classes=spec)


def test_sequence_variants_exist_in_the_g1_library(compose):
    from emopose.build import make

    library = make(compose().library, "library")  # the authored G1 set; failing to load it is a failure
    load_sequence(need(SEQUENCE), variant_classes={n: e.cls for n, e in library.snapshot.entries.items()})


def test_anchor_agreement_annotations_fit_their_items():
    """benchmarks/anchor_agreement.py's re-annotations: one anchor of 1-6 words per act, in the text, in
    order, for the same 160 sequence-suite items in each file."""
    items = {i.id: i for i in load_sequence(need(SEQUENCE))}
    folder = PROJECT_ROOT / "benchmarks/data/anchor_agreement"
    annotated = {}
    for name in ("written_1", "written_2", "plain"):
        rows = [json.loads(line) for line in need(folder / f"{name}.jsonl").open()]
        annotated[name] = [row["id"] for row in rows]
        for row in rows:
            item = items[row["id"]]
            assert len(row["anchors"]) == len(item.labels), row["id"]
            starts = [item.text.lower().find(a.lower()) for a in row["anchors"]]
            assert min(starts) >= 0 and starts == sorted(starts), (name, row["id"], row["anchors"])
            assert all(1 <= len(a.split()) <= 6 for a in row["anchors"]), (name, row["id"])
    assert len(set(annotated["written_1"])) == 160
    assert annotated["written_1"] == annotated["written_2"] == annotated["plain"]
