"""The sequencer executing timelines: keyframes on their times, strokes reported, co-articulation cuts,
and a continuous, speed-bounded stream through random timelines and interrupts."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from emopose.backends.dry_run import DryRunBackend
from emopose.clock import FakeClock
from emopose.execution.control_loop import ControlLoop
from emopose.execution.gesture_command import GestureCommand
from emopose.execution.sequencer import Sequencer, State
from emopose.execution.trajectory import TrajectoryBuilder
from emopose.stages.sequence import SequenceStage
from emopose.turn.model import Release
from emopose.turn.timeline import TimelinePlanner, TimelineSettings
from tests.core.conftest import gesture

NAMES = ("point_forward_right", "palm_stop", "chop_right", "face_wave", "shrug", "open_arms",
         "beat_both_hands", "point_up", "wave_off", "calm_down_palms")


class Rig:
    def __init__(self, library):
        self.library = library
        self.clock = FakeClock()
        self.rest = library.neutral_entry.q[0]
        self.sequencer = Sequencer(TrajectoryBuilder(library.limits), self.rest)
        self.loop = ControlLoop(self.sequencer, DryRunBackend(), self.clock)
        self.loop.begin(self.rest)
        self.stream: list[tuple[float, np.ndarray]] = []

    def run(self, seconds: float) -> None:
        for _ in range(round(seconds / self.loop.dt)):
            q = self.loop.tick()
            self.stream.append((self.clock.now(), q))

    def plan(self, gestures, onsets, speech_start: float) -> list[tuple[GestureCommand, Release]]:
        """The sequence stage's commands for a planned timeline, speech starting at speech_start."""
        planner = TimelinePlanner(TrajectoryBuilder(self.library.limits), TimelineSettings())
        timings, _ = planner.plan(gestures, onsets)
        releases = tuple(Release(t.times[0], "words", True, timing=t) if not isinstance(t, str)
                         else Release(0.0, "words", True, dropped=t) for t in timings)
        commands = [SequenceStage._command(k, g, r, speech_start)
                    for k, (g, r) in enumerate(zip(gestures, releases))]
        return sorted(zip(commands, releases), key=lambda p: p[0].release_at)

    def submit(self, gestures, onsets, speech_start: float) -> list[GestureCommand]:
        planned = self.plan(gestures, onsets, speech_start)
        for command, release in planned:
            if release.dropped:
                self.sequencer.drop(command, release.dropped, self.clock.now())
            else:
                self.sequencer.submit(command)
        return sorted((c for c, r in planned if not r.dropped), key=lambda c: c.record)

    def steps(self) -> np.ndarray:
        q = np.array([s[1] for s in self.stream])
        return np.abs(np.diff(q, axis=0))

    def events(self, kind: str):
        return [e for e in self.sequencer.events if e.kind == kind]


def test_a_timed_command_reaches_its_stroke_keyframe_at_the_planned_time(g1):
    rig = Rig(g1)
    point = gesture(g1, "point_forward_right")
    (command,) = rig.submit([point], [1.5], speech_start=0.5)
    rig.run(5.0)
    stroke = next(e for e in rig.events("stroke") if e.command_id == command.id)
    assert stroke.t == pytest.approx(0.5 + 1.5 - 0.05, abs=0.021)  # arrival: speech start + onset + lead
    keyframe = command.keyframes[command.stroke[0]]
    arrived = [t for t, q in rig.stream if np.max(np.abs(q - keyframe)) <= 0.05]
    assert arrived[0] == pytest.approx(stroke.t, abs=1e-9)
    # and the stream passes through the keyframe itself at its planned time
    at = command.release_at + command.offsets[command.stroke[0]]
    tick = min(range(len(rig.stream)), key=lambda i: abs(rig.stream[i][0] - at))
    assert np.max(np.abs(rig.stream[tick][1] - keyframe)) < 0.03
    assert rig.events("started")[0].t == pytest.approx(command.release_at, abs=0.021)


def test_coarticulated_gestures_go_from_stroke_to_stroke_without_rest(g1):
    rig = Rig(g1)
    first, second = rig.submit([gesture(g1, "point_forward_right"), gesture(g1, "palm_stop")],
                               [1.0, 2.6], 0.0)
    assert first.cut and second.blend_in
    rig.run(6.0)
    assert [e.name for e in rig.events("cut")] == ["point_forward_right"]
    assert [e.name for e in rig.events("completed")] == ["palm_stop"]
    cut_at = rig.events("cut")[0].t
    between = [q for t, q in rig.stream if cut_at - 0.2 <= t <= cut_at + 0.2]
    assert min(np.max(np.abs(q - rig.rest)) for q in between) > 0.5  # never near rest in between
    assert np.all(rig.steps() <= g1.limits.max_velocity * rig.loop.dt + 1e-9)


def test_a_late_timed_command_preempts_the_running_motion_without_a_jump(g1):
    rig = Rig(g1)
    slow = gesture(g1, "calm_down_palms")
    rig.sequencer.submit(GestureCommand("calm_down_palms", slow.keyframes, slow.duration))
    rig.run(1.0)
    rig.submit([gesture(g1, "point_left")], [0.6], speech_start=rig.clock.now())
    rig.run(4.0)
    assert rig.events("cut")[0].name == "calm_down_palms"
    assert np.all(rig.steps() <= g1.limits.max_velocity * rig.loop.dt + 1e-9)


def test_dropped_gestures_are_reported_and_never_run(g1):
    rig = Rig(g1)
    rig.submit([gesture(g1, "chop_right"), gesture(g1, "beat_both_hands")], [1.0, 1.2], 0.0)
    rig.run(6.0)
    (dropped,) = rig.events("dropped")
    assert dropped.name == "beat_both_hands" and dropped.detail.startswith("no room")
    assert [e.name for e in rig.events("started")] == ["chop_right"]


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(picks=st.lists(st.tuples(st.sampled_from(NAMES), st.integers(1, 5), st.floats(0.0, 6.0)), min_size=1,
                      max_size=4),
       interrupt_at=st.one_of(st.none(), st.floats(0.1, 6.0)),
       replacement=st.sampled_from(["nothing", "a queued motion", "a new timeline"]))
def test_random_timelines_and_interrupts_keep_the_stream_continuous(g1, picks, interrupt_at, replacement):
    rig = Rig(g1)
    gestures = [gesture(g1, name, intensity) for name, intensity, _ in picks]
    rig.submit(gestures, [onset for *_, onset in picks], speech_start=0.4)
    if interrupt_at is None:
        rig.run(12.0)
    else:
        rig.run(interrupt_at)
        follow = gesture(g1, "shrug")
        new = {"nothing": [], "a queued motion": [GestureCommand("shrug", follow.keyframes, follow.duration)],
               "a new timeline": [c for c, r in rig.plan([follow], [0.3], rig.clock.now()) if not r.dropped]}
        rig.sequencer.interrupt(new[replacement], now=rig.clock.now())
        assert len(rig.sequencer.pending) == (1 if replacement == "a new timeline" else 0)
        rig.run(10.0)
        if replacement != "nothing":
            assert rig.events("started")[-1].name == "shrug"
    assert np.all(rig.steps() <= g1.limits.max_velocity * rig.loop.dt + 1e-9)
    assert rig.sequencer.state in (State.IDLE, State.HOLDING)
    lower, upper = g1.limits.lower, g1.limits.upper
    q = np.array([s[1] for s in rig.stream])
    assert np.all(q >= lower - 1e-9) and np.all(q <= upper + 1e-9)


def test_an_interrupt_mid_stroke_blends_from_the_published_pose_and_clears_the_rest(g1):
    rig = Rig(g1)
    rig.submit([gesture(g1, "face_wave"), gesture(g1, "shrug")], [1.0, 4.0], speech_start=0.4)
    while not rig.events("stroke"):
        rig.run(rig.loop.dt)
    rig.run(0.3)  # inside the wave's stroke
    rig.sequencer.interrupt([], now=rig.clock.now())
    assert rig.sequencer.pending == [] and rig.events("stopped")[0].name == "face_wave"
    rig.run(4.0)
    assert rig.sequencer.state == State.IDLE and np.allclose(rig.sequencer.last, rig.rest, atol=1e-9)
    assert [e.name for e in rig.events("started")] == ["face_wave"]  # the shrug never started
    assert np.all(rig.steps() <= g1.limits.max_velocity * rig.loop.dt + 1e-9)


def test_a_reply_whose_triggers_are_missing_still_gets_a_timeline(g1, tmp_path):
    from emopose.contract import GestureRecord, Plan
    from tests.wiring import wire

    wired = wire(g1, tmp_path, mode="timeline")
    records = [GestureRecord(cls="welcoming", variant="face_wave", trigger="not said"),
               GestureRecord(cls="pointing", variant="point_left", trigger="nor this")]
    with wired.session:
        turn = wired.runner.run_plan(Plan.scripted("Good morning, the tour starts in five minutes.",
                                                   *records))
    releases = turn.schedule.releases
    assert [r.how for r in releases] == ["even", "even"] and not any(r.trigger_found for r in releases)
    assert all(r.timing is not None for r in releases)  # placed on the anchor equation's even spacing
    assert [e.name for e in turn.dispatched.events if e.kind == "stroke"] == ["face_wave", "point_left"]
