"""The posture layer on virtual time: postures the gestures leave from and return to, idle motion inside the
limits and speed bounds, and with rest and no idle motion exactly the stream of before."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from omegaconf import OmegaConf

from emopose.backends.dry_run import DryRunBackend
from emopose.clock import FakeClock
from emopose.config import CONFIG_DIR
from emopose.contract import EventKind
from emopose.execution.control_loop import ControlLoop
from emopose.execution.gesture_command import GestureCommand, State
from emopose.execution.posture import LISTENING, REST, THINKING, PostureSettings
from emopose.execution.sequencer import Sequencer
from emopose.execution.trajectory import TrajectoryBuilder
from emopose.robot.collision import SelfCollisionChecker
from tests.core.conftest import gesture
from tests.core.test_timeline_execution import NAMES, Rig

SHIPPED = OmegaConf.to_container(OmegaConf.load(CONFIG_DIR / "posture" / "default.yaml"))
SHIPPED.pop("_target_")


def shipped(**changes) -> PostureSettings:
    return PostureSettings(**{**SHIPPED, **changes})


class PostureRig(Rig):
    """The timeline rig with a posture layer (None: the sequencer of before)."""

    def __init__(self, library, posture: PostureSettings | None):
        self.library, self.clock = library, FakeClock()
        self.rest = library.neutral_entry.q[0]
        self.sequencer = Sequencer(TrajectoryBuilder(library.limits), self.rest, posture=posture)
        self.loop = ControlLoop(self.sequencer, DryRunBackend(), self.clock)
        self.loop.begin(self.rest)
        self.stream = []
        tick = self.loop.tick
        self.loop.tick = lambda: self.stream.append((self.clock.now(), tick())) or self.stream[-1][1]

    def run(self, seconds: float) -> None:
        for _ in range(round(seconds / self.loop.dt)):
            self.loop.tick()

    def q(self) -> np.ndarray:
        return np.array([q for _, q in self.stream])

    def assert_within_bounds(self) -> None:
        assert np.all(self.steps() <= self.library.limits.max_velocity * self.loop.dt + 1e-9)
        assert self.library.limits.violations(self.q()) == []


def untimed(library, name: str) -> GestureCommand:
    entry = library.get(name)
    return GestureCommand(name, entry.q, entry.default_duration)


def script(rig: PostureRig, g1) -> None:
    """Gestures, a timeline, an interrupt and posture requests (thinking and back between two ticks)."""
    rig.run(1.0)
    with rig.sequencer.posture.holding(THINKING):
        rig.sequencer.submit(untimed(g1, "chin_stroke"))
    rig.run(6.0)
    rig.submit([gesture(g1, "point_forward_right"), gesture(g1, "palm_stop")], [1.0, 2.6], rig.clock.now())
    rig.run(2.0)
    rig.sequencer.interrupt([], now=rig.clock.now())
    rig.submit([gesture(g1, "face_wave", 5)], [0.8], rig.clock.now())
    rig.run(8.0)


def test_at_rest_without_idle_motion_the_stream_and_events_are_those_without_a_posture_layer(g1):
    before, layered = PostureRig(g1, None), PostureRig(g1, shipped(idle_motion=False))
    for rig in (before, layered):
        script(rig, g1)
    assert np.array_equal(before.q(), layered.q())
    assert [(e.t, e.kind, e.name, e.detail) for e in before.sequencer.events] == \
        [(e.t, e.kind, e.name, e.detail) for e in layered.sequencer.events]


def test_idle_motion_is_breathing_scale_slow_and_starts_from_zero(g1):
    rig = PostureRig(g1, shipped(idle_motion=True))
    rig.run(30.0)
    excursion = np.abs(rig.q() - rig.rest)
    assert 0.02 < excursion.max() <= 0.03 + 1e-12  # a few hundredths of a radian
    assert rig.steps().max() / rig.loop.dt < 0.1  # rad/s, against bounds of 6-7 rad/s
    assert np.array_equal(rig.q()[0], rig.rest)
    assert np.abs(rig.q()[1] - rig.rest).max() < 1e-5  # fades in from zero: no step at its start


def test_a_gesture_leaves_from_the_published_pose_and_returns_to_the_current_posture(g1):
    rig = PostureRig(g1, shipped(idle_motion=True))
    listening = rig.sequencer.posture.poses[LISTENING]
    rig.sequencer.posture.request(LISTENING)
    rig.run(4.0)  # blend to listening, then idle motion
    breathing = rig.q()[-1]
    assert 0.001 < np.abs(breathing - listening).max() <= 0.03
    rig.sequencer.submit(untimed(g1, "chin_stroke"))  # its last keyframe is rest
    rig.run(0.02)
    assert np.array_equal(rig.q()[-1], breathing)  # the preparation starts where the arm is
    rig.loop.run_until(lambda: rig.sequencer.state == State.HOLDING, 10)
    assert np.allclose(rig.sequencer.last, listening, atol=1e-12)  # retracted to listening, not to rest
    rig.run(4.0)
    assert State.BLENDING not in {e.detail for e in rig.events(EventKind.STATE)[-2:]}
    assert 0.001 < np.abs(rig.q()[-1] - listening).max() <= 0.03  # breathing again, about listening
    rig.assert_within_bounds()


def test_a_posture_change_waits_for_the_gestures_and_is_recorded_when_the_arms_head_there(g1):
    rig = PostureRig(g1, shipped(idle_motion=False))
    rig.sequencer.submit(untimed(g1, "face_wave"))
    rig.run(0.5)
    rig.sequencer.posture.request(THINKING)
    rig.run(0.5)
    assert rig.events(EventKind.POSTURE) == [] and rig.sequencer.state == State.EXECUTING
    rig.loop.run_until(lambda: rig.sequencer.state == State.IDLE, 10)
    (posture,) = rig.events(EventKind.POSTURE)
    completed = rig.events(EventKind.COMPLETED)[0]
    assert posture.detail == THINKING and posture.t == completed.t  # no hold: straight to the new posture
    assert np.allclose(rig.sequencer.last, rig.sequencer.posture.poses[THINKING])
    with rig.sequencer.posture.holding(LISTENING):
        pass  # listening and back to rest between two ticks: nothing to do, nothing recorded but rest
    rig.run(2.0)
    assert [e.detail for e in rig.events(EventKind.POSTURE)] == [THINKING, REST]
    assert np.allclose(rig.sequencer.last, rig.rest)
    rig.assert_within_bounds()


@pytest.mark.parametrize("name", NAMES)
def test_idle_motion_moves_a_stroke_by_at_most_one_tick(g1, name):
    """The keyframes keep their times; a start up to 0.03 rad away can move the tick on which the arm comes
    within the stroke tolerance (chop_right: one tick of ten motions here), never more."""
    strokes = []
    for idle in (False, True):
        rig = PostureRig(g1, shipped(idle_motion=idle))
        rig.run(3.3)  # the arms breathe (or not) when the reply arrives
        rig.submit([gesture(g1, name, 4), gesture(g1, "beat_both_hands")], [0.6, 3.2], rig.clock.now())
        rig.run(9.0)
        strokes.append([(e.name, e.t) for e in rig.events(EventKind.STROKE)])
    assert strokes[0] and [n for n, _ in strokes[0]] == [n for n, _ in strokes[1]]
    assert max(abs(a - b) for (_, a), (_, b) in zip(*strokes)) <= 0.02 + 1e-9


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(picks=st.lists(st.tuples(st.sampled_from(NAMES), st.integers(1, 5), st.floats(0.0, 5.0)), min_size=1,
                      max_size=3),
       changes=st.lists(st.tuples(st.floats(0.0, 10.0), st.sampled_from([REST, LISTENING, THINKING])),
                        max_size=4),
       interrupt_at=st.one_of(st.none(), st.floats(0.1, 8.0)))
def test_postures_gestures_and_idle_motion_stay_inside_the_limits_and_speed_bounds(g1, picks, changes,
                                                                                  interrupt_at):
    rig = PostureRig(g1, shipped(idle_motion=True, fade_in_s=0.5))
    rig.run(1.5)
    rig.submit([gesture(g1, name, intensity) for name, intensity, _ in picks], [o for *_, o in picks], 1.9)
    events = sorted([*changes, *([] if interrupt_at is None else [(interrupt_at, None)])], key=lambda c: c[0])
    for at, posture in events:
        rig.run(max(at - (rig.clock.now() - 1.5), 0.0))
        if posture is None:
            rig.sequencer.interrupt([], now=rig.clock.now())
        else:
            rig.sequencer.posture.request(posture)
    rig.run(12.0)
    rig.assert_within_bounds()


def test_the_shipped_postures_are_inside_the_limits_and_clear_of_the_body(g1):
    poses = [g1.neutral_entry.q[0], np.array(SHIPPED["listening"]), np.array(SHIPPED["thinking"])]
    checker = SelfCollisionChecker(clearance=0.01)
    for a in poses:
        assert g1.limits.violations(a, 0.1) == []
        for b in poses:
            assert checker.check(a + np.linspace(0, 1, 40)[:, None] * (b - a)).ok


@pytest.mark.parametrize("change, message", [
    ({"listening": [9.0] * 14}, "posture.listening: left_shoulder_pitch_joint"),
    ({"thinking": [0.0] * 3}, "posture.thinking: needs 14"),
    ({"idle_amplitude": 0.2}, "posture.idle_amplitude=0.2"),
    ({"breath_period_s": 0.5}, "posture.breath_period_s=0.5"),
])
def test_bad_posture_settings_are_refused_naming_the_key(g1, change, message):
    with pytest.raises(ValueError, match=message.replace(".", r"\.")):
        Sequencer(TrajectoryBuilder(g1.limits), g1.neutral_entry.q[0], posture=shipped(**change))


def test_an_unknown_posture_is_refused(g1):
    sequencer = Sequencer(TrajectoryBuilder(g1.limits), g1.neutral_entry.q[0], posture=shipped())
    with pytest.raises(ValueError, match="unknown posture 'sleeping'"):
        sequencer.posture.request("sleeping")
