"""TrajectoryBuilder.build's cached-matrix fast path equals the paper's construction step by step."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from emopose.execution.trajectory import TrajectoryBuilder


def reference(builder: TrajectoryBuilder, keyframes, duration, q_last):
    """Eq. smoothstep waypoints, the speed-bound stretch, 50 Hz resampling and the limit projection."""
    waypoints = builder.waypoints(keyframes, q_last)
    spacing = duration / (len(waypoints) - 1)
    ratio = float(np.max(np.abs(np.diff(waypoints, axis=0)) / (builder.limits.max_velocity * spacing)))
    stretch = ratio * 1.001 if ratio > 1.0 else 1.0
    samples = builder.limits.project(builder.resample(waypoints, duration * stretch))
    samples[0] = q_last
    return samples, stretch


@settings(max_examples=200, deadline=None)
@given(st.integers(1, 14), st.floats(0.05, 6.0), st.integers(0, 2**32 - 1))
def test_build_matches_reference(library, frames, duration, seed):
    rng = np.random.default_rng(seed)
    builder = TrajectoryBuilder(library.limits)
    keyframes = rng.uniform(-3, 3, (frames, 14))
    q_last = library.limits.project(rng.uniform(-3.5, 3.5, 14))
    expected, stretch = reference(builder, keyframes, duration, q_last)
    for _ in range(2):  # the second build comes from the cached matrix
        trajectory = builder.build(keyframes, duration, q_last)
        assert trajectory.samples.shape == expected.shape
        np.testing.assert_allclose(trajectory.samples, expected, atol=1e-12)
        assert trajectory.stretch == np.float64(stretch) or abs(trajectory.stretch - stretch) < 1e-12
        assert trajectory.samples.flags.writeable  # callers own their samples, the cache is not shared


def test_cached_weights_are_read_only(library):
    builder = TrajectoryBuilder(library.limits)
    builder.build(np.zeros((3, 14)), 1.0, np.zeros(14))
    (weights,) = builder._weights_cache.values()
    assert not weights.flags.writeable and weights.shape == (51, 3)
