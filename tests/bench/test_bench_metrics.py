"""Single-label metrics against hand-computed values."""

import math

import numpy as np
import pytest

from emopose.bench.confusion import ConfusionPanel, confusion_counts, plot_confusion, row_normalised
from emopose.bench.metrics import (
    accuracy,
    aggregate_passes,
    mean_sd,
    paired_context_accuracy,
    tier_accuracy,
)


def test_mean_and_sample_sd():
    assert mean_sd([1.0, 2.0, 3.0]) == {"mean": 2.0, "sd": 1.0}
    assert mean_sd([70.0]) == {"mean": 70.0, "sd": None}
    assert mean_sd([]) == {"mean": None, "sd": None}
    # sample SD (ddof=1) of 96, 97, 97, 96, 98: mean 96.8, var = (0.64+0.04+0.04+0.64+1.44)/4 = 0.7
    assert mean_sd([96, 97, 97, 96, 98])["sd"] == pytest.approx(math.sqrt(0.7))


def test_accuracy_counts_failures_as_wrong():
    pairs = [("agreeing", "agreeing"), ("doubting", None), ("neutral", "pointing"), ("neutral", "neutral")]
    assert accuracy(pairs) == 50.0
    assert accuracy([]) is None


def test_tier_accuracy_over_two_passes():
    def p(tier, label, pred, k):
        return {"tier": tier, "label": label, "pred": pred, "pass": k}

    preds = [p("easy", "agreeing", "agreeing", 0), p("easy", "neutral", "neutral", 0),
             p("hard", "doubting", "neutral", 0), p("hard", "comforting", "comforting", 0),
             p("easy", "agreeing", "agreeing", 1), p("easy", "neutral", "pointing", 1),
             p("hard", "doubting", None, 1), p("hard", "comforting", "comforting", 1)]
    acc = tier_accuracy(preds, ("easy", "medium", "hard"))
    # easy: 100, 50 -> mean 75, sd sqrt(((25)^2 * 2) / 1) = 35.355; hard: 50, 50; overall: 75, 50
    assert acc["easy"]["mean"] == 75.0 and acc["easy"]["sd"] == pytest.approx(35.35533906)
    assert acc["hard"] == {"mean": 50.0, "sd": 0.0}
    assert acc["overall"]["mean"] == 62.5
    assert acc["medium"] is None


def test_aggregate_passes_skips_metrics_missing_in_a_pass():
    out = aggregate_passes([{"a": 1.0, "b": None}, {"a": 3.0, "b": 2.0}])
    assert out == {"a": {"mean": 2.0, "sd": pytest.approx(math.sqrt(2))}}


def test_paired_context_accuracy_gain_and_discordant_pairs():
    def p(label, with_, without, k):
        return {"label": label, "pred_with": with_, "pred_without": without, "pass": k}

    preds = [p("agreeing", "agreeing", "neutral", 0), p("pointing", "pointing", "pointing", 0),
             p("agreeing", "agreeing", "agreeing", 1), p("pointing", "neutral", "pointing", 1)]
    out = paired_context_accuracy(preds)
    # pass 0: with 100, without 50, gain 50; pass 1: with 50, without 100, gain -50
    assert out["with_history"]["mean"] == 75.0 and out["without_history"]["mean"] == 75.0
    assert out["gain"]["mean"] == 0.0 and out["gain"]["sd"] == pytest.approx(math.sqrt(5000))
    assert out["discordant"] == {"only_with_history": 1, "only_without_history": 1}


def test_confusion_counts_rows_are_annotated_and_failures_are_separate(tmp_path):
    counts, failed = confusion_counts([("pointing", "pointing"), ("pointing", "emphasizing"),
                                       ("neutral", "neutral"), ("neutral", None)])
    assert failed == 1 and counts.sum() == 3
    assert counts[0, 0] == 1 and counts[0, 1] == 1 and counts[7, 7] == 1
    assert np.allclose(row_normalised(counts)[0, :2], [50.0, 50.0])
    png = plot_confusion([ConfusionPanel("Easy", counts, failed)], tmp_path / "c.png")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
