"""The first-word policy: a long preparation on a reply's first word is compressed within the speed bound,
then played softer, so its stroke arrives on its word without the speech waiting past the pre-roll."""

from __future__ import annotations

import numpy as np
import pytest

from emopose.execution.trajectory import TrajectoryBuilder
from emopose.stages.first_gesture import FirstWordSettings, plan_fitting_first, softened
from tests.core.conftest import gesture
from tests.core.test_timeline import arrival, planner


def within_speed_bound(library, timing) -> bool:
    builder = TrajectoryBuilder(library.limits)
    return all(timing.times[i] - timing.times[i - 1]
               >= builder.segment_minimum(timing.keyframes[i - 1], timing.keyframes[i]) - 1e-9
               for i in range(1, len(timing.times)))


def test_a_long_preparation_on_the_first_word_arrives_in_the_window_within_both_bounds(g1):
    raise_arm = gesture(g1, "raise_arm_yes", intensity=4)
    (before,), _ = planner(g1, first_scale=0.6).plan([raise_arm], [0.0])
    assert before.fit == "late" and before.arrival_s > 0.1  # the old plan: past the window
    played, (timing,), preroll = plan_fitting_first(planner(g1), [raise_arm], [0.0], None,
                                                    FirstWordSettings())
    assert timing.fit == "softened" and played[0].intensity < 4 and played[0].name == "raise_arm_yes"
    assert preroll <= 0.4 + 1e-9 and timing.times[0] >= -0.4 - 1e-9
    assert timing.arrival_s == pytest.approx(-0.05)
    assert arrival(g1, timing, raise_arm.keyframes[0]) <= -0.05 + 0.021  # the built trajectory agrees
    assert within_speed_bound(g1, timing)
    stroke_pose = played[0].keyframes[played[0].resolved.entry.stroke_span[0]]
    assert np.allclose(timing.keyframes[timing.stroke[0]], stroke_pose)  # what is measured is what is played


def test_the_policy_can_be_switched_off_and_leaves_fitting_gestures_alone(g1):
    raise_arm = gesture(g1, "raise_arm_yes", intensity=4)
    played, (timing,), _ = plan_fitting_first(planner(g1, first_scale=0.6), [raise_arm], [0.0], None,
                                              FirstWordSettings(lowest_intensity=4))
    assert timing.fit == "late" and played[0] is raise_arm
    played, (timing,), _ = plan_fitting_first(planner(g1), [raise_arm], [2.0], None, FirstWordSettings())
    assert timing.fit == "nominal" and played[0] is raise_arm


def test_softening_pulls_the_interior_toward_the_start_pose_by_the_gain_ratio(g1):
    wave = gesture(g1, "wave_off", intensity=4)
    softer = softened(wave, 2, FirstWordSettings().gains)
    q, q0 = wave.keyframes, wave.keyframes[0]
    assert softer.intensity == 2 and np.allclose(softer.keyframes[[0, -1]], q[[0, -1]])
    assert np.allclose(softer.keyframes[1:-1], q0 + 0.6 / 1.3 * (q[1:-1] - q0))
    with pytest.raises(ValueError, match="gains"):
        FirstWordSettings(gains=(1.0, 1.0))
