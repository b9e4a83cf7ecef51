import pytest

from emopose.contract import GestureRecord, Plan
from emopose.execution.sequencer import State
from emopose.speech.listening import ListeningSettings
from tests.wiring import wire


def test_a_turn_joins_the_dialogue_history_and_the_next_turn_sees_it(wired):
    first = wired.runner.run("Welcome to the lab!")
    second = wired.runner.run("Look over there.")
    assert first.request.history == ()
    assert [m["content"] for m in second.request.history] == ["Welcome to the lab!", first.plan.reply]
    assert len(wired.runner.dialogue.messages) == 4


def test_a_prepared_answer_sees_the_question_and_the_caller_adds_what_was_said(wired):
    wired.runner.dialogue.said("This is the lab.")
    turn = wired.runner.run("Our students built it.", question="Who built that?", remember=False)
    assert [(m["role"], m["content"]) for m in turn.request.history] == [
        ("assistant", "This is the lab."), ("user", "Who built that?")]
    assert wired.runner.dialogue.messages == [{"role": "assistant", "content": "This is the lab."}]


def test_silence_stops_the_speech_and_clears_the_gestures(library, tmp_path):
    wired = wire(library, tmp_path, until="none")  # returns once the gestures are queued (web UI, tour)
    with wired.session:
        wired.runner.run("Look over there, welcome!")
        assert wired.sequencer.pending or wired.sequencer.active is not None
        stopped = []
        wired.player.stop = lambda: stopped.append(True)
        wired.runner.silence()
        assert stopped == [True] and not wired.sequencer.pending
        assert wired.sequencer.state == State.BLENDING  # from where the arm is toward neutral


def test_a_scripted_plan_enters_at_resolve_without_a_planner_call(wired):
    class NoPlanner:
        name = "none"

        def plan(self, request):
            raise AssertionError("a scripted plan must not call the planner")

    wired.runner.planner = NoPlanner()
    plan = Plan.scripted("Over there.", GestureRecord(cls="pointing", variant="pointing_b", intensity=5))
    turn = wired.runner.run_plan(plan)
    assert turn.planner_output is None and turn.plan is plan
    assert turn.resolved[0].entry.name == "pointing_b" and turn.resolved[0].rule == "exact"
    assert "parse" not in turn.stage_s and turn.dispatched.completed
    assert wired.runner.dialogue.messages == []


def test_the_session_opens_once_whoever_asks(wired):
    loop = wired.session.open()
    wired.runner.run("Hi.")
    assert wired.session.open() is loop and wired.session.is_open


def test_a_reply_the_person_waited_for_already_bounds_its_pre_roll(g1, tmp_path):
    """A spoken reply (asr.listening.reply_preroll_s): the words wait less for the first gesture, which
    still runs (softened, or late), never dropped for it."""
    wired = wire(g1, tmp_path, mode="timeline")
    with wired.session:
        typed = wired.runner.run("Welcome! The robot arm is over there.")
        spoken = wired.runner.run("Welcome! The robot arm is over there.", preroll_at_most=0.1)
    assert typed.schedule.preroll_s > 0.3 and spoken.schedule.preroll_s <= 0.1 + 1e-9
    assert [r.dropped for r in spoken.schedule.releases] == [None, None]


def test_a_negative_spoken_pre_roll_is_refused():
    with pytest.raises(ValueError, match="reply_preroll_s"):
        ListeningSettings(reply_preroll_s=-0.1)
