"""Sequence metrics against hand-computed values, including over- and under-segmentation."""

import pytest

from emopose.bench.sequence_metrics import (
    SequencePrediction,
    aligned_step_accuracy,
    anchors_recalled,
    item_scores,
    multiset_f1,
    suite_scores,
    trigger_spans,
)
from emopose.bench.suites import SequenceItem

A, B, C, D = "welcoming", "pointing", "emphasizing", "rejecting"


def item(text, labels, anchors, variants=None, ident="x"):
    variants = tuple(variants or [f"{c}_a" for c in labels])
    return SequenceItem(ident, text, tuple(labels), tuple(anchors), variants)


def test_aligned_step_accuracy_uses_the_longer_length():
    assert aligned_step_accuracy([A, B, C], [A, B, C]) == 1.0
    assert aligned_step_accuracy([A, B, C], [A, B, C, D]) == 0.75       # over-segmented: 3 of 4
    assert aligned_step_accuracy([A, B, C], [A, B]) == pytest.approx(2 / 3)  # under-segmented: 2 of 3
    assert aligned_step_accuracy([A, B], [B, A]) == 0.0                 # same multiset, wrong order
    assert aligned_step_accuracy([A, B, C], [B, C]) == 0.0              # a dropped first step shifts all


def test_multiset_f1():
    assert multiset_f1([A, B, C], [A, B, C, D]) == pytest.approx(2 * 0.75 * 1.0 / 1.75)  # P 3/4, R 1
    assert multiset_f1([A, B, C], [C]) == pytest.approx(2 * 1.0 * (1 / 3) / (4 / 3))     # P 1, R 1/3 -> 0.5
    assert multiset_f1([A, A, B], [A, B, B]) == pytest.approx(2 / 3)                      # overlap {A, B}
    assert multiset_f1([B, A], [A, B]) == 1.0                                            # order ignored
    assert multiset_f1([A], [D]) == 0.0


def test_trigger_spans_are_case_insensitive_and_repeated():
    assert trigger_spans("No, no and NO.", "no") == [(0, 2), (4, 6), (11, 13)]
    assert trigger_spans("Welcome!", None) == [] and trigger_spans("Welcome!", "  ") == []


def test_anchor_recall_needs_span_overlap():
    it = item("Welcome! Look over there, it is crucial.", [A, B, C], ["Welcome", "over there", "crucial"])
    assert anchors_recalled(it, ["welcome", "there", "crucial"]) == 3   # partial overlap counts
    assert anchors_recalled(it, ["Look", None, "important"]) == 0        # adjacent, missing, absent
    assert anchors_recalled(it, ["Look over"]) == 1                      # overlaps "over there"


def test_item_scores_over_under_and_variants():
    it = item("Hello! See that door? It is crucial.", [A, B, C], ["Hello", "that door", "crucial"])
    over = item_scores(it, SequencePrediction((A, B, C, D), ("Hello", "door", "crucial", "x"),
                                              (f"{A}_a", f"{B}_b", f"{C}_a", None)))
    assert over["over"] == 1 and over["under"] == 0 and over["exact"] == 0 and over["primary"] == 1
    assert over["aligned"] == 0.75 and over["anchors_hit"] == 3 and over["variants_hit"] == 2
    under = item_scores(it, SequencePrediction((A, C), ("Hello", "crucial"), (f"{A}_a", f"{C}_a")))
    assert under["under"] == 1 and under["aligned"] == pytest.approx(1 / 3)
    assert under["f1"] == pytest.approx(0.8)                              # P 1, R 2/3
    assert under["variants_hit"] == 1  # position 1 holds C, not B's variant
    failed = item_scores(it, SequencePrediction(None))
    assert failed["failed"] == 1 and failed["over"] == failed["under"] == 0 and failed["f1"] == 0.0


def test_suite_scores_hand_computed():
    items = [item("Hi! Over there.", [A, B], ["Hi", "Over there"], ident="s1"),
             item("No. Stop. Listen!", [D, D, C], ["No", "Stop", "Listen"], ident="s2"),
             item("Hi. Look here. Key point. No.", [A, B, C, D], ["Hi", "Look here", "Key point", "No"],
                  ident="s3")]
    preds = [SequencePrediction((A, B), ("Hi", "there"), (f"{A}_a", f"{B}_a")),          # exact
             SequencePrediction((D, C), ("No", "Listen"), (f"{D}_a", None)),             # under-segmented
             SequencePrediction(None)]                                                    # failed
    s = suite_scores(items, preds)
    assert s["primary_class"] == pytest.approx(200 / 3)
    assert s["ordered_exact"] == pytest.approx(100 / 3)
    # aligned: 1, 1/3 (D==D only), 0 -> mean 4/9
    assert s["aligned_step"] == pytest.approx(100 * 4 / 9)
    # F1: 1, (P 1, R 2/3 -> 0.8), 0 -> mean 0.6
    assert s["multiset_f1"] == pytest.approx(60.0)
    # anchors: 2 + 2 ("No", "Listen") + 0 of 9 positions; variants: 2 + 1 of 9
    assert s["anchor_recall"] == pytest.approx(400 / 9) and s["exact_variant"] == pytest.approx(300 / 9)
    assert (s["exact_len2"], s["exact_len3"], s["exact_len4"]) == (100.0, 0.0, 0.0)
    assert (s["over"], s["under"], s["failed"]) == (0, 1, 1)
    with pytest.raises(ValueError):
        suite_scores(items, preds[:2])
