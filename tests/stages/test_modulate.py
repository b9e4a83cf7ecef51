from dataclasses import replace

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from emopose.execution.trajectory import TrajectoryBuilder
from emopose.stages.modulate import INTENSITY_GAINS, LIMIT_MARGIN, modulate_keyframes


def test_hand_computed_values(library):
    q = np.zeros((3, 14))
    q[1, 0] = 1.0
    out = modulate_keyframes(q, 5, library.limits)
    assert out[1, 0] == 1.6  # q0 + 1.6 (q1 - q0)
    assert np.array_equal(out[[0, 2]], q[[0, 2]])
    assert modulate_keyframes(q, 1, library.limits)[1, 0] == 0.4


def test_projection_into_limits_with_margin(g1):
    q = np.zeros((3, 14))
    q[1, 3] = 2.0  # elbow upper limit 2.0944: 1.6 * 2.0 must clip to 2.0944 - 0.02 (the paper's delta)
    paper = replace(g1.limits, limit_margin=0.0)
    assert modulate_keyframes(q, 5, paper)[1, 3] == paper.upper[3] - LIMIT_MARGIN
    # with the tracking reserve, the target stays where commands may go (0.10 inside), or it is never reached
    assert g1.limits.limit_margin == 0.10
    assert modulate_keyframes(q, 5, g1.limits)[1, 3] == g1.limits.upper[3] - 0.10


def test_every_modulated_stroke_is_reached_by_its_commands(g1):
    """An intensity-5 stroke pose beyond the reserve's margin was clipped by the trajectory, never reached:
    61 of 951 live strokes were reported "not reached" (cross_arms_x, beckon_in, face_wave at 0.07 rad)."""
    builder = TrajectoryBuilder(g1.limits)
    rest = g1.neutral_entry.q[-1]
    for entry in g1.snapshot.entries.values():
        q = modulate_keyframes(entry.q, 5, g1.limits)
        motion = builder.build(q, entry.default_duration, rest)
        stroke = entry.stroke_span[0]  # a one-keyframe pose: its keyframe is the target
        closest = np.abs(motion.samples - q[stroke]).max(axis=1).min()
        assert closest < 0.01, f"{entry.name}: its stroke pose is {closest:.3f} rad from every command"


@settings(max_examples=200, deadline=None)
@given(st.integers(1, 5), st.lists(st.floats(-0.5, 0.5), min_size=14 * 4, max_size=14 * 4))
def test_properties(library, intensity, values):
    q = library.limits.project(np.asarray(values).reshape(4, 14) + 0.2, 0.1)
    out = modulate_keyframes(q, intensity, library.limits)
    assert np.array_equal(out[[0, -1]], q[[0, -1]]), "boundary keyframes unchanged"
    if intensity == 3:
        assert np.array_equal(out, q), "level 3 reproduces the library exactly"
    assert np.all(out >= library.limits.lower) and np.all(out <= library.limits.upper)
    margin = max(LIMIT_MARGIN, library.limits.limit_margin)
    expected = np.clip(q[0] + INTENSITY_GAINS[intensity - 1] * (q[1:-1] - q[0]),
                       library.limits.lower + margin, library.limits.upper - margin)
    if intensity != 3:
        assert np.allclose(out[1:-1], expected)


def test_duration_invariant(library):
    from emopose.contract import GestureRecord
    from emopose.stages.modulate import Modulate
    from emopose.stages.resolve import resolve_record

    stage = Modulate(library.limits)
    durations = {stage.modulate(resolve_record(GestureRecord(cls="agreeing", variant="agreeing_a",
                                                             intensity=i), library)).duration
                 for i in range(1, 6)}
    assert durations == {library.get("agreeing_a").default_duration}
