"""Where a planner's triggers start against the annotated anchors (the words each gesture belongs to).

The timeline aims a gesture's stroke at its trigger's first word (the contract: a trigger is the lexical
affiliate and starts at the word the stroke belongs on), so a trigger that starts at its clause instead
of its affiliate moves the stroke off the words it depicts even when it overlaps them. For each gold
anchor of a sequence-suite item:

- its gesture is the planned record whose trigger (located as the schedule locates it: first
  occurrence, case-insensitive) overlaps the anchor most; with none overlapping, the record at the
  anchor's position when the plan has as many records as there are anchors; otherwise it has none;
- the signed offset is that trigger's spoken onset minus the anchor's (engine word events; negative:
  the trigger starts earlier). An anchor without a gesture, or a trigger not in the text, has no offset
  and counts as outside the window.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from emopose.contract import trigger_position
from emopose.speech.espeak_lib import WordEvent
from emopose.speech.word_events import onset_of_span
from emopose.sync.strokes import StrokeSync

WINDOW_S = 0.2  # the target: the trigger onset within 200 ms of the anchor onset


def _overlap(a: tuple[int, int], b: tuple[int, int]) -> int:
    return max(0, min(a[1], b[1]) - max(a[0], b[0]))


def trigger_spans(text: str, triggers: Sequence[str | None]) -> list[tuple[int, int] | None]:
    """Each trigger's span in the text where the schedule finds it (first occurrence), or None."""
    spans: list[tuple[int, int] | None] = []
    for trigger in triggers:
        pos = trigger_position(text, trigger)
        spans.append(None if pos is None or not trigger else (pos, pos + len(trigger)))
    return spans


def gesture_of_anchor(anchor: tuple[int, int], k: int, spans: list[tuple[int, int] | None],
                      anchors: int) -> int | None:
    """The index of the record that belongs to the k-th anchor (module docstring), or None."""
    overlaps = [(_overlap(anchor, s), -i) for i, s in enumerate(spans) if s is not None]
    best = max(overlaps, default=(0, 0))
    if best[0] > 0:
        return -best[1]
    return k if len(spans) == anchors and spans[k] is not None else None


def anchor_offsets(text: str, anchors: Sequence[tuple[int, int]], triggers: Sequence[str | None],
                   events: Sequence[WordEvent]) -> list[float | None]:
    """Per gold anchor: its gesture's trigger onset minus the anchor onset (s), or None (no gesture)."""
    spans = trigger_spans(text, triggers)
    offsets: list[float | None] = []
    for k, anchor in enumerate(anchors):
        gesture = gesture_of_anchor(anchor, k, spans, len(anchors))
        gold = onset_of_span(text, events, *anchor)
        span = spans[gesture] if gesture is not None else None
        onset = onset_of_span(text, events, *span) if span is not None else None
        offsets.append(None if onset is None or gold is None else onset - gold)
    return offsets


def offset_summary(offsets: Sequence[float | None], window_s: float = WINDOW_S) -> dict:
    """Share of anchors whose trigger onset is within +-window_s of theirs, and the signed distribution
    (ms) over the anchors that have a gesture."""
    measured = np.array([o for o in offsets if o is not None], dtype=float) * 1000.0
    n = len(offsets)
    within = int(np.sum(np.abs(measured) <= window_s * 1000.0 + 1e-6))
    summary = {"anchors": n, "with_gesture": int(measured.size), "within": within,
               "within_share": within / n if n else None, "window_ms": window_s * 1000.0,
               "early_share": float(np.mean(measured < -window_s * 1000.0)) if measured.size else None,
               "late_share": float(np.mean(measured > window_s * 1000.0)) if measured.size else None}
    if measured.size:
        percentiles = np.percentile(measured, [5, 25, 50, 75, 95])
        summary |= {"mean_signed_ms": float(measured.mean()), "min_ms": float(measured.min()),
                    "max_ms": float(measured.max())}
        summary |= {f"p{p}_ms": float(v) for p, v in zip((5, 25, 50, 75, 95), percentiles)}
    return summary


def gold_anchor_strokes(item: str, text: str, anchors: Sequence[tuple[int, int] | None],
                        triggers: Sequence[str | None], strokes: Sequence[StrokeSync],
                        events: Sequence[WordEvent]) -> list[StrokeSync]:
    """Per gold anchor, its gesture's measured stroke (strokes[k] belongs to triggers[k]) against the
    anchor's onset: what stroke_summary then reads as stroke-vs-gold-anchor. An anchor without a
    gesture keeps its onset and no stroke, so it counts as planned and not arrived; one that is not in
    the text (None; the say-do check reports it) has no onset and is not counted."""
    spans = trigger_spans(text, triggers)
    rows = []
    for k, anchor in enumerate(anchors):
        if anchor is None:
            rows.append(StrokeSync(item, k, "", None, None, None, None, "anchor not in the text", 0.0))
            continue
        gesture = gesture_of_anchor(anchor, k, spans, len(anchors))
        onset = onset_of_span(text, events, *anchor)
        stroke = strokes[gesture] if gesture is not None and gesture < len(strokes) else None
        preroll = strokes[0].preroll_s if strokes else 0.0
        rows.append(replace(stroke, k=k, onset_s=onset) if stroke is not None else
                    StrokeSync(item, k, "", onset, None, None, None, "no gesture", preroll))
    return rows
