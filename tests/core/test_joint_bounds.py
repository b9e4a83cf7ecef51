"""emopose.sync.joint_bounds: excursions past the limits and speed ratios of a measured stream."""

from __future__ import annotations

import numpy as np
import pytest

from emopose.sync.joint_bounds import joint_bounds


def test_a_stream_inside_both_bounds_reports_nothing(g1):
    limits = g1.limits
    times = np.arange(10) * 0.02
    q = np.tile((limits.lower + limits.upper) / 2, (10, 1))
    q[:, 3] += 0.5 * limits.max_velocity[3] * times  # half the speed bound
    report = joint_bounds(times, q, limits)
    assert report["beyond_limits_max_rad"] == 0.0 and report["samples_beyond_limits"] == 0
    assert report["speed_ratio_max"] == pytest.approx(0.5)
    assert report["samples_above_speed_bound"] == 0


def test_overshoot_and_overspeed_are_measured(g1):
    limits = g1.limits
    times = np.arange(3) * 0.02
    q = np.tile(limits.upper, (3, 1)) - 0.1
    q[1, 0] = limits.upper[0] + 0.03  # 30 mrad past the upper limit
    q[2, 0] = q[1, 0] - 1.2 * limits.max_velocity[0] * 0.02  # back at 1.2x the bound
    report = joint_bounds(times, q, limits)
    assert report["beyond_limits_max_rad"] == pytest.approx(0.03)
    assert report["samples_beyond_limits"] == 1
    first = 0.13 / 0.02 / limits.max_velocity[0]  # 0.13 rad in 20 ms, then 1.2x the bound
    assert report["speed_ratio_max"] == pytest.approx(max(first, 1.2))
    assert report["speed_ratio_worst_joint"] == limits.names[0]
    assert report["samples_above_speed_bound"] == 1 + (first > 1.05)
