"""Trigger onsets against the gold anchors, in speech time (emopose/sync/affiliate.py)."""

import re

from emopose.speech.espeak_lib import WordEvent
from emopose.sync.affiliate import anchor_offsets, gold_anchor_strokes, offset_summary
from emopose.sync.strokes import StrokeSync

TEXT = "The planetarium is up those stairs. No, you can't bring food."


def events(text: str, seconds_per_word: float = 0.3) -> list[WordEvent]:
    return [WordEvent(m.start(), len(m.group()), round(k * seconds_per_word, 6))
            for k, m in enumerate(re.finditer(r"\S+", text))]


def spans(*phrases: str) -> list[tuple[int, int]]:
    return [(TEXT.index(p), TEXT.index(p) + len(p)) for p in phrases]


ANCHORS = spans("up those stairs", "you can't bring food")


def test_a_trigger_starting_at_its_clause_is_early_for_its_anchor():
    offsets = anchor_offsets(TEXT, ANCHORS, ["The planetarium is up", "No, you can't"], events(TEXT))
    assert [round(o, 3) for o in offsets] == [-0.9, -0.3]
    summary = offset_summary(offsets)
    assert summary["within"] == 0 and summary["early_share"] == 1.0


def test_triggers_on_the_affiliate_are_within_the_window():
    offsets = anchor_offsets(TEXT, ANCHORS, ["up those stairs", "you can't bring"], events(TEXT))
    assert offsets == [0.0, 0.0] and offset_summary(offsets)["within_share"] == 1.0


def test_bad_triggers_have_defined_outcomes():
    # a trigger not in the reply, an empty or missing one: that anchor has no gesture (counts as a miss)
    offsets = anchor_offsets(TEXT, ANCHORS, ["the lobby", None], events(TEXT))
    assert offsets == [None, None]
    assert offset_summary(offsets)["within"] == offset_summary(offsets)["with_gesture"] == 0
    # a plan as long as the anchors pairs them by position when nothing overlaps
    assert anchor_offsets(TEXT, ANCHORS, ["The planetarium", "No"], events(TEXT))[0] == -0.9
    assert anchor_offsets(TEXT, [], ["up those stairs"], events(TEXT)) == []
    assert offset_summary([])["within_share"] is None


def test_strokes_are_measured_against_the_anchor_their_gesture_belongs_to():
    strokes = [StrokeSync("x", 0, "point_up", 0.9, 0.85, 0.86, None, None, 0.4)]
    rows = gold_anchor_strokes("x", TEXT, ANCHORS, ["up those stairs"], strokes, events(TEXT))
    assert rows[0].onset_s == 0.9 and rows[0].executed_s == 0.86
    assert rows[1].executed_s is None and rows[1].dropped == "no gesture"  # planned, never arrived
