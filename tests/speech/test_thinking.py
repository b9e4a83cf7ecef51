"""Latency masking: the thinking motion plays while the planner works and the plan interrupts it."""

from __future__ import annotations

import json

import numpy as np
import pytest

from emopose.backends.dry_run import DryRunBackend
from emopose.clock import FakeClock
from emopose.context import RunContext
from emopose.pipeline import Pipeline
from emopose.planners.base import PlannerOutput
from emopose.sequencer import GestureCommand, Sequencer
from emopose.stages.dispatch import Dispatch
from emopose.stages.modulate import Modulate
from emopose.stages.parse import Parse
from emopose.stages.resolve import Resolve
from emopose.stages.schedule import ScheduleStage
from emopose.stages.sequence import SequenceStage
from emopose.thinking import ThinkingGesture
from emopose.trajectory import TrajectoryBuilder

REPLY = "Welcome to the lab! The robot arm is over there."
PLAN = json.dumps({"reply": REPLY, "gestures": [
    {"class": "welcoming", "variant": "welcoming_a", "intensity": 4, "trigger": "Welcome"},
    {"class": "pointing", "variant": "pointing_b", "intensity": 3, "trigger": "over there"}]})


class RecordingBackend(DryRunBackend):
    def __init__(self) -> None:
        super().__init__()
        self.stream: list[np.ndarray] = []

    def send(self, t, q) -> None:
        super().send(t, q)
        self.stream.append(np.array(q))


class SlowPlanner:
    """Planning takes `latency_s` of stream time: the control loop keeps publishing meanwhile."""

    name = "slow"

    def __init__(self, latency_s: float) -> None:
        self.latency_s, self.ctx = latency_s, None

    def plan(self, request) -> PlannerOutput:
        self.ctx.loop.run_until(lambda: False, self.latency_s)
        return PlannerOutput(raw=PLAN, latency_s=self.latency_s)


def make_ctx(library, espeak, tmp_path, latency_s, thinking=True):
    planner = SlowPlanner(latency_s)
    stages = [Parse(), Resolve(), Modulate(), ScheduleStage(mode="words"), SequenceStage(), Dispatch(until="rest")]
    ctx = RunContext(library=library, planner=planner, pipeline=Pipeline(stages), backend=RecordingBackend(),
                     sequencer=Sequencer(TrajectoryBuilder(library.limits), library.neutral_entry.q[0]),
                     clock=FakeClock(), speech=espeak, run_dir=tmp_path, record=False,
                     thinking=ThinkingGesture("doubting_a", repeats=3, library=library) if thinking else None)
    planner.ctx = ctx
    return ctx


def events_of(ctx, kind, name=None):
    return [e for e in ctx.sequencer.events if e.kind == kind and (name is None or e.name == name)]


@pytest.mark.parametrize("latency_s", [0.6, 1.3])  # mid-motion; in the blend between two repeats
def test_plan_interrupts_thinking_and_the_stream_stays_within_the_speed_bound(library, espeak, tmp_path, latency_s):
    ctx = make_ctx(library, espeak, tmp_path, latency_s=latency_s)
    turn = ctx.run_turn("Hello robot, where is the arm?")
    thinking_started = events_of(ctx, "started", "doubting_a")
    assert thinking_started and thinking_started[0].t < 0.05  # began right away, while planning
    assert all(e.t < latency_s for e in thinking_started)  # no repeat after the plan arrived
    if latency_s < 1.0:  # doubting_a lasts 1 s: the first repeat was still running
        stopped = events_of(ctx, "stopped", "doubting_a")
        assert len(stopped) == 1 and stopped[0].t == pytest.approx(latency_s, abs=0.021)
    # the plan's gestures still start at their scheduled releases (within one tick)
    speech_start = turn.submitted.speech_start
    for command, release in zip(turn.submitted.commands, turn.schedule.releases):
        started = [e.t for e in events_of(ctx, "started") if e.command_id == command.id]
        assert started and 0 <= started[0] - (speech_start + release.release_s) <= 0.02 + 1e-9
    stream = np.array(ctx.backend.stream)
    bound = library.limits.max_velocity * ctx.loop.dt
    assert np.all(np.abs(np.diff(stream, axis=0)) <= bound + 1e-9)
    assert np.allclose(stream[-1], library.neutral_entry.q[0], atol=0.02)  # came back to rest


def test_fast_planner_leaves_no_trace_of_thinking(library, espeak, tmp_path):
    ctx = make_ctx(library, espeak, tmp_path, latency_s=0.0)
    ctx.run_turn("Hello robot")
    assert not events_of(ctx, "started", "doubting_a")
    assert [e.name for e in events_of(ctx, "started")] == ["welcoming_a", "pointing_b"]


def test_busy_sequencer_is_not_disturbed(library, espeak, tmp_path):
    ctx = make_ctx(library, espeak, tmp_path, latency_s=0.0)
    ctx.open()
    entry = library.get("comforting_a")
    ctx.sequencer.submit(GestureCommand(entry.name, entry.q, entry.default_duration))
    ctx.loop.tick()
    assert ctx.thinking.start(ctx) == set()


def test_unknown_motion_is_refused_at_build_time(library):
    with pytest.raises(ValueError, match="thinking.motion 'chin_strok'"):
        ThinkingGesture("chin_strok", library=library)
