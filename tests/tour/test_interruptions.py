"""Visitor questions: they clear pending gestures, stop the base, get answered, and the tour resumes."""

from __future__ import annotations

import numpy as np
import pytest

from emopose.execution.sequencer import Sequencer
from emopose.tour.interruptions import Interruptions, asks_about_scene, wants_abort
from emopose.tour.scenario_loading import parse_tour
from tests.tour.tour_helpers import small, tour_runner

AT_NEUTRAL_RAD = 0.03  # the G1's plain law (kp 60, tau = 0) leaves the resting arms ~0.025 rad below neutral


def test_intents():
    assert wants_abort("Could you please stop the tour?") and wants_abort("Let's end the tour here")
    assert not wants_abort("Is the robot going to stop?")
    assert asks_about_scene("What is this?") and asks_about_scene("what am I looking at")
    assert not asks_about_scene("Who built these robots?")


def test_scripted_questions_fire_once_in_their_place_and_live_ones_at_once():
    spec = parse_tour(small(interruptions=[{"at_stop": "second", "after_s": 2.0, "text": "Why?"},
                                           {"during_leg": "second", "text": "Where to?"}]))
    questions = Interruptions(spec.interruptions)
    assert questions.poll("stop", "second", 1.9) is None and questions.poll("stop", "first", 5.0) is None
    assert questions.poll("stop", "second", 2.0).text == "Why?"
    assert questions.poll("stop", "second", 9.0) is None  # once only
    questions.ask("How tall are you?")
    assert questions.poll("leg", "first", 0.0).text == "How tall are you?"
    assert [q.text for q in questions.unasked] == ["Where to?"]


class InterruptSpy:
    """Records what the sequencer held each time it was interrupted."""

    def __init__(self, sequencer: Sequencer) -> None:
        self.calls, self._interrupt = [], sequencer.interrupt

        def spy(commands=(), now=None):
            self.calls.append({"pending": len(sequencer.pending), "active": sequencer.active is not None,
                               "commands": len(commands), "now": now})
            self._interrupt(commands, now)
            self.calls[-1]["state_after"] = sequencer.state.value

        sequencer.interrupt = spy


def test_a_question_during_narration_clears_answers_and_resumes(tmp_path):
    raw = small(interruptions=[{"at_stop": "first", "after_s": 2.5, "text": "Who made that box?",
                                "answer": "Our students made it. Look at it over there!"}])
    with tour_runner(tmp_path, raw) as (run, tour):
        spy = InterruptSpy(run.resources.sequencer)
        report = tour.run()
        history = list(run.runner.dialogue.messages)
    cut = next(c for c in spy.calls if c["now"] is not None)
    assert cut["pending"] + cut["active"] >= 1  # gestures were queued or running ...
    assert cut["commands"] == 0 and cut["state_after"] == "blending"  # ... and were cleared with a blend
    first = report.stops[0]
    assert first.interruptions == 1 and len(report.exchanges) == 1
    exchange = report.exchanges[0]
    assert exchange.answer.startswith("Our students made it") and exchange.gestures  # spoken with gestures
    assert not exchange.base_moving_when_asked and not exchange.image_attached
    # Resumed from the interrupted sentence: the second piece of narration starts a sentence of the first.
    assert len(first.narration) == 2 and first.narration[1] in first.narration[0]
    assert first.narration[1].startswith(("Hello", "Look", "It is"))
    assert all(s.reached and s.within_tolerance for s in report.stops) and report.ended_at_rest
    roles = [(h["role"], h["content"][:12]) for h in history]
    question_at = roles.index(("user", "Who made tha"))
    assert (roles[question_at - 1][0] == "assistant"
            and roles[question_at + 1] == ("assistant", "Our students"))
    assert roles[-1][0] == "assistant" and len(history) >= 5  # the dialogue spans the whole tour


def test_a_question_while_walking_stops_the_base_first_then_the_leg_resumes(tmp_path):
    raw = small(interruptions=[{"during_leg": "second", "after_s": 1.5, "text": "How fast can you walk?",
                                "answer": "Indoors I walk slowly, for safety."}])
    with tour_runner(tmp_path, raw) as (run, tour):
        speeds = []
        answer = tour.answer

        def spying_answer(question):
            speeds.append(tour.base.true_velocity())
            return answer(question)

        tour.answer = spying_answer
        report = tour.run()
    assert speeds and all(abs(v) < 0.02 for v in speeds[0])  # at rest before answering
    exchange = report.exchanges[0]
    assert exchange.base_moving_when_asked and exchange.where == "leg:second"
    second = report.stops[1]
    assert second.reached and second.within_tolerance and second.pauses == 1
    assert second.gestures_while_walking == 0  # answers while walking are given standing, arms then rest
    assert report.ended_at_rest


def test_stop_the_tour_aborts_and_leaves_the_robot_at_rest(tmp_path):
    raw = small(interruptions=[{"at_stop": "first", "after_s": 3.0,
                                "text": "Sorry, please stop the tour now."},
                               {"at_stop": "second", "text": "Never asked"}])
    with tour_runner(tmp_path, raw) as (run, tour):
        report = tour.run()
        neutral = run.resources.library.neutral_entry.q[0]
        measured = run.resources.backend.measured()
        moving = tour.base.moving()
    assert report.aborted and len(report.stops) == 1 and report.exchanges[0].aborted
    assert report.exchanges[0].answer.startswith("Of course, we will end the tour")
    assert report.unasked == ["Never asked"]
    assert report.ended_at_rest and not moving
    assert np.max(np.abs(measured - neutral)) < AT_NEUTRAL_RAD  # arms at neutral


@pytest.mark.parametrize("gesture_while_walking", [False, True])
def test_lines_said_while_walking_gesture_only_when_allowed(tmp_path, gesture_while_walking):
    raw = small(gesture_while_walking=gesture_while_walking)  # stop 2 has an approach line with cues
    with tour_runner(tmp_path, raw) as (run, tour):
        report = tour.run()
    walking = report.stops[1].gestures_while_walking
    assert (walking > 0) == gesture_while_walking
    assert all(s.within_tolerance for s in report.stops)


class FailingPlanner:
    """Plans the first line, then fails: the tour must still leave the robot at rest."""

    name = "failing"

    def __init__(self, inner) -> None:
        self.inner, self.calls = inner, 0

    def plan(self, request):
        self.calls += 1
        if self.calls > 1:
            raise RuntimeError("planner crashed")
        return self.inner.plan(request)


def test_a_failure_mid_tour_still_ends_with_the_base_stopped_and_arms_at_neutral(tmp_path):
    raw = small(stops=[dict(small()["stops"][0], narration="Hello and welcome! Look at the box over there. "
                            "It is really important. " * 4)])
    with tour_runner(tmp_path, raw) as (run, tour):
        run.runner.planner = FailingPlanner(run.runner.planner)
        with pytest.raises(RuntimeError, match="planner crashed"):
            tour.run()
        neutral = run.resources.library.neutral_entry.q[0]
        assert tour.report.ended_at_rest and not tour.base.moving()
        assert np.max(np.abs(run.resources.backend.measured() - neutral)) < AT_NEUTRAL_RAD
