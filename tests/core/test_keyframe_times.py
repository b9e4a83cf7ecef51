"""A library motion's own keyframe times (`times:`): validated where the file enters, followed by the
trajectory builder, refused by Pose Studio when the speed bound forbids them; without them, every shipped
motion builds exactly as before."""

from __future__ import annotations

import hashlib
import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from emopose.execution.trajectory import TrajectoryBuilder
from emopose.joint_limits import LibraryError
from emopose.stages.modulate import Modulate
from emopose.stages.sequence import SequenceStage
from emopose.studio.authoring import PoseStudio
from emopose.turn.model import Release
from emopose.turn.timeline import TimelinePlanner, TimelineSettings
from tests.conftest import REST, load_library, make_library_dir, write_motion
from tests.core.conftest import gesture

GOLDEN = Path(__file__).with_name("shipped_trajectories.json")
UP = [*REST[:7], -0.9, -0.5, *REST[9:]]  # the right arm raised forward-out


@pytest.mark.parametrize("extra,needle", [
    ({"times": [0.0, 0.5]}, "2 times for 3 keyframes"),
    ({"times": [0.1, 0.5, 1.0]}, "times[0] is 0.1"),
    ({"times": [0.0, 0.6, 0.6]}, "K2 at 0.6 s must come at least 0.02 s"),
    ({"times": [0.0, 0.5, 25.0]}, "at most 20.0 s"),
    ({"times": [0.0, 0.5, 1.0], "duration": 1.0}, "not both"),
])
def test_bad_times_name_the_file_and_the_field(tmp_path, extra, needle):
    folder = make_library_dir(tmp_path / "lib")
    write_motion(folder, "timed_badly", "agreeing", [REST, UP, REST], **extra)
    with pytest.raises(LibraryError) as info:
        load_library(folder)
    message = str(info.value)
    assert "timed_badly.yaml" in message and "times" in message and needle in message
    assert "\n" not in message


def test_a_pose_has_no_keyframe_times(tmp_path):
    folder = make_library_dir(tmp_path / "lib")
    write_motion(folder, "timed_pose", "agreeing", [UP], motion_type="pose", times=[0.0])
    with pytest.raises(LibraryError, match="timed_pose.yaml.*times.*a pose has no keyframe times"):
        load_library(folder)


def test_the_builder_reaches_each_keyframe_at_its_time(library):
    builder, rest = TrajectoryBuilder(library.limits), np.asarray(REST)
    keyframes = np.array([REST, UP, UP, REST])
    even = builder.build(keyframes, 1.5, rest)
    assert np.allclose(builder.build(keyframes, 1.5, rest, (0.0, 0.5, 1.0, 1.5)).samples, even.samples,
                       atol=1e-12)  # evenly spaced times are the rule's spacing
    timed = builder.build(keyframes, 2.0, rest, (0.0, 0.4, 1.6, 2.0))
    assert timed.anchor_ticks == (0, 20, 80, 100) and timed.stretch == 1.0
    assert np.allclose(timed.samples[[20, 80, 100]], keyframes[1:])
    assert np.allclose(timed.samples[20:81], UP)  # held between K1 and K2, as written


def test_a_timing_too_fast_is_slowed_uniformly_keeping_its_rhythm(library):
    builder = TrajectoryBuilder(library.limits)
    fast = builder.build(np.array([REST, UP, REST]), 0.2, np.asarray(REST), (0.0, 0.05, 0.2))
    assert fast.stretch > 1.0
    assert fast.anchor_ticks == tuple(builder.tick(t * fast.stretch) for t in (0.0, 0.05, 0.2))  # all later
    assert fast.late_s == 0.0
    steps = np.abs(np.diff(fast.samples, axis=0)) / builder.dt
    assert np.all(steps <= library.limits.max_velocity * 1.001)


def test_studio_refuses_times_the_speed_bound_forbids_naming_time_and_joint(library):
    studio = PoseStudio(library)
    entry = studio.draft([REST, UP, REST], times=[0.0, 0.05, 1.0])
    report = studio.report(entry)
    assert report.timing_faults and not any(studio.report(studio.draft([REST, UP, REST])).timing_faults)
    assert report.problems[0].startswith("keyframe times too fast for the joint speed bound: K1 at 0.05 s")
    assert "right_shoulder_pitch_joint needs" in report.problems[0]
    assert report.refusal_at(3) == report.problems[0]


def test_the_time_a_refusal_names_is_rounded_up_so_that_typing_it_is_allowed(library):
    builder = TrajectoryBuilder(library.limits)
    needed = builder.segment_minimum(np.asarray(UP), np.asarray(REST))
    shown = np.ceil(needed * 100 - 1e-9) / 100
    assert shown - 0.01 < needed < shown  # the bound falls between two hundredths here
    fault, = builder.timing_faults(np.array([REST, UP, REST]), (0.0, 0.5, 0.5 + shown - 0.01))
    assert f"needs {shown:.2f} s" in fault
    assert builder.timing_faults(np.array([REST, UP, REST]), (0.0, 0.5, 0.5 + shown)) == []


# -- shipped motions: no times, so exactly today's trajectories --------------------------------------
def _digest(array: np.ndarray, decimals: int | None = None) -> str:
    values = np.asarray(array, dtype=float) if decimals is None else np.round(array, decimals) + 0.0
    return hashlib.sha256(values.tobytes()).hexdigest()[:16]


def shipped_digests(g1) -> dict[str, list[str]]:
    """Per shipped motion: its keyframes' digest, and its level 3 and 5 trajectories' from rest (to 1e-7 rad:
    any change of the construction shows, float noise of another BLAS does not)."""
    builder, modulate, rest = TrajectoryBuilder(g1.limits), Modulate(g1.limits), g1.neutral_entry.q[0]
    out = {}
    for entry in g1.snapshot.entries.values():
        runs = [builder.build(modulate.keyframes(entry.q, level), entry.default_duration, rest, entry.times)
                for level in (3, 5)]
        out[entry.name] = [_digest(np.append(entry.q, entry.default_duration)),
                           *(_digest(np.append(run.samples, run.anchor_ticks), 7) for run in runs)]
    return out


def test_shipped_motions_build_exactly_as_before(g1):
    """Regenerate after a deliberate change: GOLDEN.write_text(json.dumps(shipped_digests(g1), indent=0))."""
    golden, now = json.loads(GOLDEN.read_text()), shipped_digests(g1)
    unchanged = [name for name in now if name in golden and golden[name][0] == now[name][0]]
    assert len(unchanged) >= 20, "most shipped motions changed since the golden digests: regenerate them"
    assert {name: now[name] for name in unchanged} == {name: golden[name] for name in unchanged}
    studio, rest = PoseStudio(g1), g1.neutral_entry.q[0]
    for entry in g1.snapshot.entries.values():
        assert entry.times is None
        report = studio.report(entry, 5)
        plain = studio.builder.build(report.keyframes, entry.default_duration, rest)
        assert np.array_equal(report.trajectory.samples, plain.samples)


def test_a_replys_timeline_keeps_the_motions_own_keyframe_times(tmp_path):
    folder = make_library_dir(tmp_path / "lib")
    write_motion(folder, "timed_raise", "agreeing", [REST, UP, UP, REST], times=[0.0, 0.4, 1.6, 2.0],
                 stroke=[1, 2])
    write_motion(folder, "even_raise", "agreeing", [REST, UP, UP, REST], duration=2.0, stroke=[1, 2])
    library = load_library(folder)
    planner = TimelinePlanner(TrajectoryBuilder(library.limits), TimelineSettings())
    (timed, even), _ = planner.plan([gesture(library, "timed_raise"), gesture(library, "even_raise")],
                                    [2.0, 8.0])
    assert timed.fit == even.fit == "nominal"
    assert np.allclose(np.diff(timed.times), [0.4, 1.2, 0.4])  # as written, not an even 2/3 s each
    assert np.allclose(np.diff(even.times), 2.0 / 3.0)


def test_an_untimed_command_builds_with_the_motions_own_times(tmp_path):
    folder = make_library_dir(tmp_path / "lib")
    write_motion(folder, "timed_raise", "agreeing", [REST, UP, UP, REST], times=[0.0, 0.4, 1.6, 2.0])
    modulated = gesture(load_library(folder), "timed_raise")
    slower = replace(modulated, duration=4.0)  # a schedule that stretches the motion keeps its rhythm
    command = SequenceStage._command(0, slower, Release(0.0, "words", True), 0.0)
    assert not command.timed and command.authored_times == pytest.approx((0.0, 0.8, 3.2, 4.0))
