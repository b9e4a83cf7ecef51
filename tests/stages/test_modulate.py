import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from emopose.stages.modulate import INTENSITY_GAINS, LIMIT_MARGIN, modulate_keyframes


def test_hand_computed_values(library):
    q = np.zeros((3, 14))
    q[1, 0] = 1.0
    out = modulate_keyframes(q, 5, library.limits)
    assert out[1, 0] == 1.6  # q0 + 1.6 (q1 - q0)
    assert np.array_equal(out[[0, 2]], q[[0, 2]])
    assert modulate_keyframes(q, 1, library.limits)[1, 0] == 0.4


def test_projection_into_limits_with_margin(library):
    q = np.zeros((3, 14))
    q[1, 3] = 2.0  # elbow upper limit 2.0944: 1.6 * 2.0 must clip to 2.0944 - 0.02
    out = modulate_keyframes(q, 5, library.limits)
    assert out[1, 3] == library.limits.upper[3] - LIMIT_MARGIN


@settings(max_examples=200, deadline=None)
@given(st.integers(1, 5), st.lists(st.floats(-0.5, 0.5), min_size=14 * 4, max_size=14 * 4))
def test_properties(library, intensity, values):
    q = library.limits.project(np.asarray(values).reshape(4, 14) + 0.2, 0.1)
    out = modulate_keyframes(q, intensity, library.limits)
    assert np.array_equal(out[[0, -1]], q[[0, -1]]), "boundary keyframes unchanged"
    if intensity == 3:
        assert np.array_equal(out, q), "level 3 reproduces the library exactly"
    assert np.all(out >= library.limits.lower) and np.all(out <= library.limits.upper)
    expected = np.clip(q[0] + INTENSITY_GAINS[intensity - 1] * (q[1:-1] - q[0]),
                       library.limits.lower + LIMIT_MARGIN, library.limits.upper - LIMIT_MARGIN)
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
