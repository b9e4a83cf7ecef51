"""Latency masking: the thinking motion plays while the planner works and the plan interrupts it."""

from __future__ import annotations

import json

import numpy as np
import pytest

from emopose.backends.dry_run import DryRunBackend
from emopose.execution.gesture_command import GestureCommand
from emopose.planners.base import PlannerOutput
from emopose.turn.thinking import ThinkingGesture
from tests.wiring import wire

REPLY = "Welcome to the lab! The robot arm is over there."
PLAN = json.dumps({"reply": REPLY, "gestures": [
    {"class": "welcoming", "variant": "welcoming_a", "intensity": 4, "trigger": "Welcome"},
    {"class": "pointing", "variant": "pointing_b", "intensity": 3, "trigger": "over there"}]})


class RecordingBackend(DryRunBackend):
    def __init__(self) -> None:
        super().__init__()
        self.stream: list[np.ndarray] = []

    def send(self, t, q) -> np.ndarray:
        q = super().send(t, q)
        self.stream.append(np.array(q))
        return q


class SlowPlanner:
    """Planning takes `latency_s` of stream time: the control loop keeps publishing meanwhile."""

    name = "slow"

    def __init__(self, latency_s: float, raw: str = PLAN) -> None:
        self.latency_s, self.raw, self.loop = latency_s, raw, None

    def plan(self, request) -> PlannerOutput:
        self.loop.run_until(lambda: False, self.latency_s)
        return PlannerOutput(raw=self.raw, latency_s=self.latency_s)


def make_run(library, espeak, tmp_path, latency_s, mode="words", plan=PLAN, thinking="doubting_a"):
    planner = SlowPlanner(latency_s, plan)
    run = wire(library, tmp_path, planner=planner, synthesizer=espeak, backend=RecordingBackend(), mode=mode,
               record=False)
    planner.loop = run.loop
    run.runner.thinking = ThinkingGesture(library, run.sequencer, run.loop.clock, thinking, repeats=3)
    return run


def events_of(run, kind, name=None):
    return [e for e in run.sequencer.events if e.kind == kind and (name is None or e.name == name)]


@pytest.mark.parametrize("latency_s", [0.6, 1.3])  # mid-motion; in the blend between two repeats
def test_plan_interrupts_thinking_and_the_stream_stays_within_the_speed_bound(library, espeak, tmp_path,
                                                                              latency_s):
    run = make_run(library, espeak, tmp_path, latency_s=latency_s)
    turn = run.runner.run("Hello robot, where is the arm?")
    thinking_started = events_of(run, "started", "doubting_a")
    assert thinking_started and thinking_started[0].t < 0.05  # began right away, while planning
    assert all(e.t < latency_s for e in thinking_started)  # no repeat after the plan arrived
    if latency_s < 1.0:  # doubting_a lasts 1 s: the first repeat was still running
        stopped = events_of(run, "stopped", "doubting_a")
        assert len(stopped) == 1 and stopped[0].t == pytest.approx(latency_s, abs=0.021)
    # the plan's gestures still start at their scheduled releases (within one tick)
    speech_start = turn.submitted.speech_start
    for command, release in zip(turn.submitted.commands, turn.schedule.releases):
        started = [e.t for e in events_of(run, "started") if e.command_id == command.id]
        assert started and 0 <= started[0] - (speech_start + release.release_s) <= 0.02 + 1e-9
    stream = np.array(run.loop.backend.stream)
    bound = library.limits.max_velocity * run.loop.dt
    assert np.all(np.abs(np.diff(stream, axis=0)) <= bound + 1e-9)
    assert np.allclose(stream[-1], library.neutral_entry.q[0], atol=0.02)  # came back to rest


def test_fast_planner_leaves_no_trace_of_thinking(library, espeak, tmp_path):
    run = make_run(library, espeak, tmp_path, latency_s=0.0)
    run.runner.run("Hello robot")
    assert not events_of(run, "started", "doubting_a")
    assert [e.name for e in events_of(run, "started")] == ["welcoming_a", "pointing_b"]


def test_busy_sequencer_is_not_disturbed(library, espeak, tmp_path):
    run = make_run(library, espeak, tmp_path, latency_s=0.0)
    run.session.open()
    entry = library.get("comforting_a")
    run.sequencer.submit(GestureCommand(entry.name, entry.q, entry.default_duration))
    run.loop.tick()
    assert run.runner.thinking.start() == set()


def test_unknown_motion_is_refused_at_build_time(library, tmp_path):
    run = wire(library, tmp_path)
    with pytest.raises(ValueError, match="thinking.motion 'chin_strok'"):
        ThinkingGesture(library, run.sequencer, run.loop.clock, "chin_strok")



@pytest.mark.parametrize("latency_s", [0.6, 2.5])  # mid-motion; mid-blend between two repeats
def test_a_first_gesture_starting_from_the_thinking_pose_lands_where_the_timeline_planned_it(
        g1, espeak, tmp_path, latency_s):
    """The plan interrupts the thinking gesture and its first stroke is on the first word, so that gesture
    prepares from wherever the arm is; the timeline, told the arm's pose, plans for it (it used to plan
    from rest and the stroke came ~180 ms after its planned time)."""
    plan = json.dumps({"reply": REPLY, "gestures": [
        {"class": "doubting", "variant": "palm_tilt_waver", "intensity": 3, "trigger": "Welcome"}]})
    run = make_run(g1, espeak, tmp_path, latency_s, mode="timeline", plan=plan, thinking="chin_stroke")
    turn = run.runner.run("Hello robot, where is the arm?")
    assert events_of(run, "started", "chin_stroke")
    first = turn.submitted.commands[0]
    arrival = turn.submitted.speech_start + turn.schedule.releases[0].timing.arrival_s
    stroke = [e.t for e in events_of(run, "stroke") if e.command_id == first.id]
    # never later than planned but for the 50 Hz quantisation (the start and the arrival each fall on a
    # tick: up to two periods, as without thinking); a little early where the arm started closer to the
    # stroke than the farthest pose planned for
    assert stroke and -0.1 <= stroke[0] - arrival <= 2 * run.loop.dt + 1e-9
