import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from emopose.execution.trajectory import TrajectoryBuilder, blend_weight, smoothstep


def test_smoothstep_and_blend_curves():
    assert smoothstep(0.0) == 0 and smoothstep(1.0) == 1 and smoothstep(0.5) == 0.5
    assert smoothstep(0.2) == pytest.approx(3 * 0.04 - 2 * 0.008)
    u = np.array([0.0, 0.25, 0.5, 0.75, 1.0])
    assert np.allclose(blend_weight(u), [0.0, 4 * 0.25**3, 0.5, 1 - 0.5 * 0.5**3, 1.0])


def test_waypoints_hand_computed(library):
    builder = TrajectoryBuilder(library.limits)
    q_last = np.zeros(14)
    keyframes = np.zeros((3, 14))
    keyframes[1, 0], keyframes[2, 0] = 1.0, 0.5
    w = builder.waypoints(keyframes, q_last)
    assert w.shape == (11, 14)  # q_last + 2 segments x 5 increments
    s = [smoothstep(r / 5) for r in range(1, 6)]
    assert np.allclose(w[1:6, 0], s)  # first segment starts at q_last (replaces q~_0)
    assert np.allclose(w[6:11, 0], [1.0 - 0.5 * v for v in s])


def test_resampling_at_50hz_ends_on_last_keyframe(library):
    builder = TrajectoryBuilder(library.limits)
    keyframes = np.zeros((3, 14))
    keyframes[1, 0] = 0.3
    traj = builder.build(keyframes, 1.01, np.zeros(14))
    assert len(traj.samples) == 52  # ceil(1.01 / 0.02) + 1
    assert traj.duration == pytest.approx(1.02)
    assert np.allclose(traj.samples[-1], keyframes[-1])
    mid = traj.samples[np.argmin(np.abs(np.arange(52) * 0.02 - 0.505))]
    assert mid[0] == pytest.approx(0.3, abs=0.01)


@settings(max_examples=150, deadline=None)
@given(st.lists(st.floats(-4, 4), min_size=14, max_size=14),
       st.lists(st.floats(-1.5, 1.5), min_size=14 * 4, max_size=14 * 4), st.floats(0.3, 5.0))
def test_every_sample_in_limits_and_first_sample_is_last_published(library, q_last, frames, duration):
    builder = TrajectoryBuilder(library.limits)
    q_last = library.limits.project(np.asarray(q_last))
    traj = builder.build(np.asarray(frames).reshape(4, 14), duration, q_last)
    assert np.array_equal(traj.samples[0], q_last)
    assert np.all(traj.samples >= library.limits.lower) and np.all(traj.samples <= library.limits.upper)
    steps = np.abs(np.diff(traj.samples, axis=0))
    assert np.all(steps <= library.limits.max_velocity * builder.dt + 1e-9), "speed bound respected"


def test_fast_motion_is_stretched_not_sped_up(library):
    builder = TrajectoryBuilder(library.limits)
    keyframes = np.zeros((3, 14))
    keyframes[1, 0] = 2.5
    traj = builder.build(keyframes, 0.5, np.zeros(14))
    assert traj.stretch > 1.0 and traj.duration > 0.5


def test_blend_is_paper_curve_and_bounded(library):
    builder = TrajectoryBuilder(library.limits)
    a, b = np.zeros(14), np.full(14, 0.2)
    blend = builder.blend(a, b, 0.3)
    assert len(blend.samples) == 16 and blend.duration == pytest.approx(0.3)
    assert np.allclose(blend.samples[-1], b) and np.array_equal(blend.samples[0], a)
    long = builder.blend(a, np.full(14, 1.5), 0.3)  # 3 * 1.5 / 8 rad/s = 0.5625 s needed
    assert long.duration >= 0.56
