"""The training's ETA covers every pass still to come (planners/local/training.py Remaining)."""

from emopose.planners.local.training import Remaining


def test_the_eta_counts_the_epochs_after_the_frozen_pass(monkeypatch):
    clock = iter([0.0, 1.0, 2.0, 5.0])  # construction, two frozen batches of 1 s, then an epoch batch of 3 s
    monkeypatch.setattr("emopose.planners.local.training.time.perf_counter", lambda: next(clock))
    remaining = Remaining(frozen=3, epoch=4, trainable_layers=2)
    remaining.step("frozen")
    # 2 frozen batches at 1 s, 4 epoch batches estimated at 2 layers x EPOCH_COST_PER_LAYER s each
    assert remaining.step("frozen") == f"0:{round(1 + 4 * 2 * Remaining.EPOCH_COST_PER_LAYER):02d}"
    assert remaining.step("epoch") == "0:10"  # 1 frozen at 1 s + 3 epoch batches at the measured 3 s
