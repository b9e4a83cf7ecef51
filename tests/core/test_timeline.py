"""The stroke-synchronous timeline planner on the shipped G1 library: every documented fitting rule."""

from __future__ import annotations

import numpy as np
import pytest

from emopose.build import safety_check
from emopose.execution.trajectory import TrajectoryBuilder
from emopose.library import MotionLibrary
from emopose.robot.collision import SelfCollisionChecker
from emopose.turn.timeline import TimelinePlanner, TimelineSettings
from tests.core.conftest import gesture


def planner(library: MotionLibrary, safety=None, **settings) -> TimelinePlanner:
    return TimelinePlanner(TrajectoryBuilder(library.limits), TimelineSettings(**settings), safety)


def arrival(library: MotionLibrary, timing, start_pose: np.ndarray, tolerance: float = 0.05) -> float:
    """Where the planned trajectory (built as the sequencer builds it) first comes within tolerance of
    the stroke-start keyframe, in s from speech start."""
    builder = TrajectoryBuilder(library.limits)
    times = np.asarray(timing.times[1:]) - timing.times[0]
    motion = builder.build_timed(timing.keyframes, times, start_pose, timing.blend_in)
    close = np.max(np.abs(motion.samples - timing.keyframes[timing.stroke[0]]), axis=1) <= tolerance
    return timing.times[0] + np.flatnonzero(close)[0] * builder.dt


def test_a_lone_gesture_is_prepared_backwards_so_its_stroke_arrives_just_before_the_word(g1):
    point = gesture(g1, "point_forward_right")
    (timing,), preroll = planner(g1).plan([point], [2.0])
    assert timing.fit == "nominal" and preroll == 0.0
    assert timing.arrival_s == pytest.approx(2.0 - 0.05)
    # the trajectory the sequencer will build really arrives there (to the 20 ms tick)
    assert arrival(g1, timing, point.keyframes[0]) == pytest.approx(1.95, abs=0.021)
    assert timing.times[0] < 1.95 - 0.5  # the preparation starts well before the word


def test_a_trigger_on_the_first_word_delays_the_speech_by_a_bounded_preroll(g1):
    point = gesture(g1, "point_forward_right")
    (timing,), preroll = planner(g1).plan([point], [0.0])
    assert 0 < preroll <= 0.4 and timing.times[0] == pytest.approx(-preroll)
    assert timing.fit in ("scaled", "late") and 0.4 <= timing.scale < 1.0
    (capped,), preroll = planner(g1, max_preroll_s=0.1).plan([point], [0.0])
    assert preroll == pytest.approx(0.1) and capped.fit == "late" and capped.arrival_s > capped.target_s


def test_overlapping_gestures_coarticulate_from_the_previous_stroke_end(g1):
    first, second = gesture(g1, "point_forward_right"), gesture(g1, "palm_stop")
    (a, b), _ = planner(g1).plan([first, second], [1.0, 2.8])
    assert a.cut and len(a.times) == a.stroke[1] + 1  # cut after its stroke end: no retraction
    assert b.fit == "coarticulated" and b.blend_in and b.times[0] >= a.times[-1] - 1e-9
    assert b.arrival_s == pytest.approx(2.8 - 0.05)
    assert arrival(g1, b, a.keyframes[-1]) == pytest.approx(2.75, abs=0.021)


def test_a_closer_trigger_shortens_the_previous_stroke(g1):
    first, second = gesture(g1, "point_forward_right"), gesture(g1, "palm_stop")
    (a, b), _ = planner(g1).plan([first, second], [1.0, 2.0])
    assert b.fit == "shortened" and len(a.times) == a.stroke[0] + 1  # cut at its stroke start
    assert b.arrival_s == pytest.approx(2.0 - 0.05)


def test_far_apart_gestures_each_return_to_rest(g1):
    (a, b), _ = planner(g1).plan([gesture(g1, "point_left"), gesture(g1, "shrug")], [1.0, 6.0])
    assert not a.cut and a.fit == b.fit == "nominal" and b.times[0] >= a.times[-1]


def test_back_to_back_triggers_200_ms_apart_drop_the_later_one_with_a_reason(g1):
    (a, b), _ = planner(g1).plan([gesture(g1, "chop_right"), gesture(g1, "beat_both_hands")], [1.0, 1.2])
    assert not isinstance(a, str)
    assert isinstance(b, str) and b.startswith("no room") and "chop_right" in b


def test_a_long_motion_before_a_close_trigger_is_shortened_or_the_next_dropped(g1):
    long, quick = gesture(g1, "idle_breathe"), gesture(g1, "point_left")  # a 5 s motion, then 0.5 s later
    (a, b), _ = planner(g1).plan([long, quick], [0.8, 1.3])
    if isinstance(b, str):
        assert "no room" in b
    else:
        assert b.fit in ("coarticulated", "shortened") and a.cut
        assert a.times[-1] <= b.times[0] + 1e-9


def test_gestures_are_placed_in_word_order_whatever_the_record_order(g1):
    (late, early), _ = planner(g1).plan([gesture(g1, "shrug"), gesture(g1, "point_left")], [5.0, 1.0])
    assert early.times[0] < late.times[0]


def test_every_segment_respects_the_speed_bound_and_the_scale_bounds(g1):
    builder = TrajectoryBuilder(g1.limits)
    rng = np.random.default_rng(3)
    names = [n for n in g1.names if g1.get(n).motion_type == "sequence"]
    for _ in range(60):
        chosen = [gesture(g1, str(rng.choice(names)), int(rng.integers(1, 6)))
                  for _ in range(rng.integers(1, 5))]
        onsets = np.sort(rng.uniform(0.0, 6.0, len(chosen))).tolist()
        timings, preroll = planner(g1).plan(chosen, onsets)
        assert 0.0 <= preroll <= 0.4 + 1e-9
        placed = sorted((t for t in timings if not isinstance(t, str)), key=lambda t: t.times[0])
        for previous, timing in zip([None, *placed], placed):
            assert previous is None or timing.times[0] >= previous.times[-1] - 1e-9
            low = 0.4 if previous is None else 0.6  # a reply's first preparation: down to first_scale
            assert low - 1e-9 <= timing.scale <= 1.3 + 1e-9
            poses = np.array(timing.keyframes)
            if timing.blend_in:
                poses[0] = previous.keyframes[-1]  # it starts from where the previous one was cut
            for i in range(1, len(timing.times)):
                shortest = builder.segment_minimum(poses[i - 1], poses[i], timing.blend_in and i == 1)
                assert timing.times[i] - timing.times[i - 1] >= shortest - 1e-9


def refuse_blends(rest: np.ndarray):
    """A safety check that refuses every path not starting at rest (every co-articulation blend)."""
    return lambda samples: None if np.allclose(samples[0], rest) else "arms collide"


def test_an_unsafe_coarticulation_blend_falls_back_to_rest_or_a_drop(g1):
    first, second = gesture(g1, "point_forward_right"), gesture(g1, "palm_stop")
    (a, b), _ = planner(g1, safety=refuse_blends(first.keyframes[0])).plan([first, second], [1.0, 2.2])
    assert not a.cut  # never blended
    assert isinstance(b, str) and "unsafe (arms collide)" in b or not b.blend_in


def test_an_unsafe_direct_blend_is_kept_through_a_safe_via_pose(g1):
    first, second = gesture(g1, "point_forward_right"), gesture(g1, "palm_stop")
    rest = first.keyframes[0]
    # a safety check that passes only paths through the rest pose in their first half (every motion
    # retracts to rest at its end): the direct blends and the halfway via fail
    through_rest = lambda samples: (  # noqa: E731
        None if np.min(np.max(np.abs(samples[:len(samples) // 2] - rest), axis=1)) < 1e-3 else "arms collide")
    (a, b), _ = planner(g1, safety=through_rest).plan([first, second], [1.0, 2.6])
    assert b.fit == "via_rest" and b.blend_in and a.cut
    assert np.allclose(b.keyframes[1], rest)  # the via pose, before the preparation
    assert b.stroke == tuple(i + 1 for i in second.resolved.entry.stroke_span)
    assert arrival(g1, b, a.keyframes[-1]) == pytest.approx(2.6 - 0.05, abs=0.021)
    builder = TrajectoryBuilder(g1.limits)
    poses = [a.keyframes[-1], *b.keyframes[1:]]
    for i in range(1, len(b.times)):
        assert b.times[i] - b.times[i - 1] >= builder.segment_minimum(poses[i - 1], poses[i], i == 1) - 1e-9
    (_, dropped), _ = planner(g1, safety=refuse_blends(rest)).plan([first, second], [1.0, 2.6])
    assert "unsafe (arms collide) and no safe via pose fits" in dropped


def test_a_motion_the_safety_check_refuses_at_every_timing_is_dropped_with_the_reason(g1):
    """self_hug at intensity 4 brings a forearm within 5 mm of the other hand from rest, whatever its
    timing: the timeline drops it with the check's reason instead of handing the sequencer a motion it
    would refuse at dispatch (the schedule's softening then plays it softer: test_softening)."""
    check = safety_check(SelfCollisionChecker(clearance=0.01))
    hug, point = gesture(g1, "self_hug", intensity=4), gesture(g1, "point_forward_right")
    (dropped, placed), _ = planner(g1, safety=check).plan([hug, point], [1.0, 4.0])
    assert dropped.startswith("unsafe: the safety check refuses every timing that fits (left_forearm vs")
    assert check(built(g1, placed, placed.keyframes[0])) is None
    (_, after), _ = planner(g1, safety=check).plan([point, hug], [1.0, 4.0])  # not a blend's fault either
    assert after.startswith("unsafe: the safety check refuses every timing that fits, even from rest (")
    (at_three,), _ = planner(g1, safety=check).plan([gesture(g1, "self_hug")], [1.0])
    assert not isinstance(at_three, str) and check(built(g1, at_three, at_three.keyframes[0])) is None


def test_two_hands_together_poses_are_joined_through_a_pose_with_the_hands_parted(g1):
    """hands_clasped then hands_on_heart: the direct blends, rest and the halfway via all pass the hands
    within the check's 10 mm of each other (the live run dropped 4 of 320 turns' hands_on_heart so);
    rolling both shoulders outward first parts them, and the whole path passes the real check."""
    check = safety_check(SelfCollisionChecker(clearance=0.01))
    clasped, heart = gesture(g1, "hands_clasped"), gesture(g1, "hands_on_heart")
    (a, b), _ = planner(g1, safety=check).plan([clasped, heart], [1.0, 2.5])
    assert b.fit == "via_apart" and a.cut  # the blends, rest and halfway (tried first) were all refused
    assert arrival(g1, b, a.keyframes[-1]) == pytest.approx(2.5 - 0.05, abs=0.021)
    assert check(built(g1, b, a.keyframes[-1])) is None


def built(library, timing, start: np.ndarray) -> np.ndarray:
    """The samples the sequencer builds for a placed gesture starting at `start`."""
    times = np.asarray(timing.times[1:]) - timing.times[0]
    builder = TrajectoryBuilder(library.limits)
    return builder.build_timed(timing.keyframes, times, start, timing.blend_in).samples


def test_settings_are_validated():
    with pytest.raises(ValueError, match="scale"):
        TimelineSettings(scale=(1.2, 1.3))
    with pytest.raises(ValueError, match="preroll"):
        TimelineSettings(max_preroll_s=-1)
    with pytest.raises(ValueError, match="first_scale"):
        TimelineSettings(first_scale=0.7)
