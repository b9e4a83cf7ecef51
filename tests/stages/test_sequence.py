"""The sequence stage: gestures into the sequencer's queue, released against the planned speech start."""

import numpy as np

from emopose.contract import GestureRecord, Plan
from emopose.execution.sequencer import State
from emopose.planners.base import PlanRequest
from emopose.speech.clip import SpeechClip
from emopose.stages.sequence import SequenceStage
from emopose.turn.model import Turn
from tests.wiring import wire


def scheduled_turn(run, reply="Welcome! Look over there.", records=None):
    records = records or (GestureRecord(cls="welcoming", trigger="Welcome"),
                          GestureRecord(cls="pointing", trigger="over there"))
    turn = Turn(PlanRequest(reply), plan=Plan.scripted(reply, *records))
    for stage in run.stages[1:4]:  # resolve, modulate, schedule
        values = stage(turn)
        for name, value in zip(stage.writes, values if len(stage.writes) > 1 else (values,)):
            setattr(turn, name, value)
    return turn


def test_commands_are_queued_at_speech_start_plus_their_release(library, tmp_path):
    run = wire(library, tmp_path)
    run.loop.clock.advance(3.0)
    turn = scheduled_turn(run)
    submission = run.stages[4](turn)
    assert submission.speech_start == 3.0  # the null sink: heard the moment it starts
    assert [c.release_at for c in submission.commands] == [3.0 + r.release_s for r in turn.schedule.releases]
    assert [c.name for c in run.sequencer.pending] == [g.name for g in turn.modulated]
    assert [c.label for c in submission.commands] == ["welcoming", "pointing"]
    assert np.array_equal(submission.commands[0].keyframes, turn.modulated[0].keyframes)
    assert len(submission.submission_s) == 2


def test_a_device_latency_moves_the_planned_speech_start(library, tmp_path):
    class SlowDevice:
        def expected_latency_s(self, clip, clock):
            return 0.25

    run = wire(library, tmp_path)
    stage = SequenceStage(run.sequencer, run.loop.clock, SlowDevice())
    turn = scheduled_turn(run)
    assert stage(turn).speech_start == 0.25


def test_interrupt_replaces_what_is_queued(library, tmp_path):
    run = wire(library, tmp_path, record=False)
    run.session.open()
    first = scheduled_turn(run)
    run.stages[4](first)
    interrupting = SequenceStage(run.sequencer, run.loop.clock, run.player, interrupt=True)
    second = scheduled_turn(run, "No.", (GestureRecord(cls="rejecting", trigger="No"),))
    submission = interrupting(second)
    assert run.sequencer.pending == []  # the first turn's gestures are gone
    assert run.sequencer.state == State.BLENDING  # toward the new gesture's first keyframe
    run.loop.run_until(lambda: run.sequencer.active is not None, 2.0)
    assert run.sequencer.active.id == submission.commands[0].id
    assert len(submission.submission_s) == 1  # one hand-off: the interrupt


def test_empty_speech_still_releases_at_once(library, tmp_path):
    run = wire(library, tmp_path)
    turn = scheduled_turn(run, "", (GestureRecord(cls="agreeing"),))
    turn.speech = SpeechClip(text="", duration_s=0.0)
    assert run.stages[4](turn).commands[0].release_at == run.loop.clock.now()
