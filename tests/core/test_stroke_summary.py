"""The stroke measure's summary: window membership, drops and the statistics over arrived strokes."""

from __future__ import annotations

import pytest

from emopose.sync.strokes import StrokeSync, stroke_summary


def stroke(k: int, onset: float, executed: float | None, dropped: str | None = None) -> StrokeSync:
    return StrokeSync("item", k, "motion", onset, None, executed, None, dropped, preroll_s=0.0)


def test_strokes_on_the_window_edges_count_inside_despite_float_noise():
    # 0.1 s computed the way stream times are (sums of ticks plus offsets) lands a hair past 0.1
    noisy_late = sum([0.02] * 5) + 3.6e-13
    rows = [stroke(0, 0.0, noisy_late), stroke(1, 1.0, 1.0 - 0.2 - 4e-13), stroke(2, 2.0, 2.0 + 0.1 + 2e-3),
            stroke(3, 3.0, 3.0 - 0.2 - 2e-3)]
    summary = stroke_summary(rows)
    assert summary["within_window_share"] == 0.5  # the two on the edges in, the two 2 ms outside out


def test_dropped_and_unarrived_strokes_count_against_the_share_but_not_the_statistics():
    rows = [stroke(0, 0.0, 0.03), stroke(1, 1.0, 0.95), stroke(2, 2.0, None, dropped="no room"),
            stroke(3, 3.0, None)]
    summary = stroke_summary(rows)
    assert summary["n"] == 4 and summary["arrived"] == 2
    assert summary["within_window_share"] == 0.5 and summary["dropped_share"] == 0.25
    assert (summary["median_abs_ms"] == pytest.approx(40.0)
            and summary["median_signed_ms"] == pytest.approx(-10.0))
