"""Command/state alignment, N-point resampling and Eq. sim-MAE on hand-made streams."""

from __future__ import annotations

import numpy as np
import pytest

from emopose.backends.dry_run import DryRunBackend
from emopose.backends.stream_tap import StreamTap
from emopose.jobs.tracking import latency_ms, resample, sim_mae, tracking_error


def test_resample_keeps_endpoints_and_is_linear():
    stream = np.linspace(0, 1, 51)[:, None] * np.arange(1, 15)
    out = resample(stream, 100)
    assert out.shape == (100, 14)
    np.testing.assert_allclose(out[0], stream[0])
    np.testing.assert_allclose(out[-1], stream[-1])
    np.testing.assert_allclose(np.diff(out[:, 0]), 1 / 99)  # uniform in time


def test_tick_alignment_vs_time_alignment():
    commands = np.linspace(0, 1, 51)[:, None].repeat(14, axis=1)  # a ramp, 0.02 rad per tick
    states = commands.copy()  # the servo reaches each target by the end of its period
    error = tracking_error(commands, states)
    assert error.mae == pytest.approx(0.0) and error.max_abs == pytest.approx(0.0)
    # Wall-clock pairing compares that state with the next command: one tick of lag.
    assert error.mae_time_aligned == pytest.approx(0.02)


def test_sim_mae_weighs_every_trial_equally():
    short = tracking_error(np.zeros((11, 14)), np.full((11, 14), 0.1))
    long = tracking_error(np.zeros((201, 14)), np.zeros((201, 14)))
    assert sim_mae([short, long]) == pytest.approx(0.05)


def test_tap_forwards_and_records():
    tap = StreamTap(DryRunBackend())
    tap.connect(None)
    tap.send(0.02, np.ones(14))
    assert tap.name == "dry_run" and len(tap) == 1 and tap.backend.sent == 1
    np.testing.assert_array_equal(tap.states[0], np.ones(14))
    assert tap.tick_at(0.021) == 0
    with pytest.raises(LookupError):
        tap.tick_at(0.5)


def test_latency_summary():
    stats = latency_ms([0.001] * 19 + [0.002])
    assert stats["mean"] == pytest.approx(1.05) and stats["p95"] == pytest.approx(1.05) and stats["n"] == 20
    assert latency_ms([])["mean"] is None
