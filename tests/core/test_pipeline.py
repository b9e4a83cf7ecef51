import pytest

from emopose.contract import GestureRecord, Plan
from emopose.planners.base import PlanRequest
from emopose.recording import read_recording
from emopose.turn.model import Turn
from emopose.turn.pipeline import Pipeline, PipelineError


def test_misordered_or_ablated_pipeline_is_refused_before_any_model_call(wired):
    order = list(wired.stages)
    order[1], order[2] = order[2], order[1]
    with pytest.raises(PipelineError, match="stage 'modulate' reads \\['resolved'\\]"):
        Pipeline(order)
    with pytest.raises(PipelineError, match="'schedule' reads"):
        Pipeline([s for s in wired.stages if s.name != "modulate"])


def test_a_stage_naming_a_field_the_turn_does_not_have_is_refused(wired):
    class Typo:
        name, reads, writes = "typo", ("plan",), ("resolvd",)

        def __call__(self, turn):
            return []

    with pytest.raises(PipelineError, match="resolvd"):
        Pipeline([wired.stages[0], Typo()])


def test_step_through_fills_the_typed_turn_field_by_field(wired):
    wired.session.open()
    turn = Turn(PlanRequest("Welcome to the lab! No, don't touch that."))
    wired.runner.plan(turn, wired.runner.planner)
    names = [name for name, _ in wired.runner.pipeline.step_through(turn)]
    assert names == ["plan", "resolved", "modulated", "speech", "schedule", "submitted", "dispatched"]
    assert [r.cls for r in turn.plan.records] == ["welcoming", "rejecting"]
    assert turn.dispatched.completed
    started = [e for e in turn.dispatched.events if e.kind == "started"]
    assert [e.name for e in started] == ["welcoming_a", "rejecting_a"]
    assert started[0].t <= turn.schedule.releases[1].release_s <= started[1].t
    assert set(turn.stage_s) == {"planner", *[s.name for s in wired.stages]}


def test_hooks_run_after_every_stage_in_order(wired):
    seen = []
    pipeline = Pipeline(wired.stages, hooks=[lambda stage, turn: seen.append((stage.name, stage.writes[-1]))])
    wired.session.open()
    turn = Turn(PlanRequest("Hello"), plan=Plan.scripted("Hello there.", GestureRecord(cls="welcoming")))
    pipeline.run(turn, start="resolve")
    assert [name for name, _ in seen] == ["resolve", "modulate", "schedule", "sequence", "dispatch"]
    assert all(getattr(turn, written) is not None for _, written in seen)


def test_starting_later_needs_the_fields_that_stage_reads(wired):
    with pytest.raises(PipelineError, match="reads \\['resolved'\\]"):
        Pipeline(wired.stages).run(Turn(PlanRequest("Hi")), start="modulate")
    with pytest.raises(PipelineError, match="cannot start at 'aim'"):
        Pipeline(wired.stages).run(Turn(PlanRequest("Hi")), start="aim")


def test_turn_to_json_holds_every_written_field(wired):
    turn = wired.runner.run("Welcome! Look over there.")
    data = turn.to_json()
    assert set(data) == {"request", "planner_output", "plan", "resolved", "modulated", "speech", "schedule",
                         "submitted", "dispatched", "stage_ms"}
    assert data["resolved"][0]["resolved"] == turn.resolved[0].entry.name
    assert data["submitted"]["commands"][1]["release_at"] == turn.submitted.commands[1].release_at


def test_the_runner_records_each_value_when_its_stage_writes_it(wired, tmp_path):
    turn = wired.runner.run("Welcome to the lab! No, don't touch that.")
    wired.session.close()
    recording = read_recording(tmp_path / "session.mcap")
    fields = ["request", "planner_output", "plan", "resolved", "modulated", "speech", "schedule", "submitted",
              "dispatched"]
    assert {"/joints/command", *[f"/{f}" for f in fields]} <= set(recording)
    assert recording["/plan"][0][1]["records"][0]["class"] == "welcoming"
    assert recording["/resolved"][0][1]["resolved"][1]["resolved"] == turn.resolved[1].entry.name
    # the plan is recorded before execution starts; dispatch's report after the motion has run
    assert recording["/plan"][0][0] < recording["/dispatched"][0][0]
    times = [t for t, _ in recording["/joints/command"]]
    assert all(b > a for a, b in zip(times, times[1:]))


def test_a_pipeline_from_resolve_on_takes_a_plan_as_input(wired):
    with pytest.raises(PipelineError, match="reads \\['plan'\\]"):
        Pipeline(wired.stages[1:])
    tail = Pipeline(wired.stages[1:], inputs=("request", "plan"))
    wired.session.open()
    turn = tail.run(Turn(PlanRequest("Hi"), plan=Plan.scripted("Hi!", GestureRecord(cls="welcoming"))))
    assert turn.dispatched.completed and turn.resolved[0].entry.cls == "welcoming"


def test_a_turn_missing_what_the_first_stage_reads_is_refused_before_it_runs(wired):
    tail = Pipeline(wired.stages[1:], inputs=("request", "plan"))
    with pytest.raises(PipelineError, match="reads \\['plan'\\]"):
        tail.run(Turn(PlanRequest("Hi")))
