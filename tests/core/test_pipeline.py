import pytest

from emopose.backends.dry_run import DryRunBackend
from emopose.clock import FakeClock
from emopose.context import RunContext
from emopose.pipeline import Pipeline, PipelineError
from emopose.planners.keyword import KeywordPlanner
from emopose.sequencer import Sequencer
from emopose.speech.clip import EstimatedSpeech
from emopose.stages.dispatch import Dispatch
from emopose.stages.modulate import Modulate
from emopose.stages.parse import Parse
from emopose.stages.resolve import Resolve
from emopose.stages.schedule import ScheduleStage
from emopose.stages.sequence import SequenceStage
from emopose.trajectory import TrajectoryBuilder


def stages():
    return [Parse(), Resolve(), Modulate(), ScheduleStage(), SequenceStage(), Dispatch()]


def test_misordered_or_ablated_pipeline_is_refused_before_any_model_call():
    order = stages()
    order[1], order[2] = order[2], order[1]
    with pytest.raises(PipelineError, match="stage 'modulate' reads \\['resolved'\\]"):
        Pipeline(order)
    with pytest.raises(PipelineError, match="'schedule' reads"):
        Pipeline([s for s in stages() if s.name != "modulate"])


def test_step_through_shows_every_value_and_records_to_mcap(library, tmp_path):
    from emopose.recording import read_recording

    ctx = RunContext(library=library, planner=KeywordPlanner(), pipeline=Pipeline(stages()),
                     backend=DryRunBackend(), clock=FakeClock(), speech=EstimatedSpeech(), run_dir=tmp_path,
                     sequencer=Sequencer(TrajectoryBuilder(library.limits), library.neutral_entry.q[0]))
    with ctx:
        ctx.open()
        turn = ctx.new_turn("Welcome to the lab! No, don't touch that.")
        names = [name for name, _ in ctx.pipeline.step_through(turn, ctx, ctx.planner)]
        ctx.record_turn(turn)
    assert names == ["planner_output", "plan", "resolved", "modulated", "schedule", "submitted", "dispatched"]
    assert [r.cls for r in turn.plan.records] == ["welcoming", "rejecting"]
    assert turn.dispatched.completed
    started = [e for e in turn.dispatched.events if e.kind == "started"]
    assert [e.name for e in started] == ["welcoming_a", "rejecting_a"]
    assert started[0].t <= turn.schedule.releases[1].release_s <= started[1].t
    recording = read_recording(tmp_path / "session.mcap")
    assert {"/joints/command", "/plan", "/resolved", "/schedule"} <= set(recording)
    times = [t for t, _ in recording["/joints/command"]]
    assert all(b > a for a, b in zip(times, times[1:]))
    assert recording["/plan"][0][1]["records"][0]["class"] == "welcoming"
