"""The dispatch stage: starts the audio, then runs the loop until the awaited sequencer state."""

from dataclasses import replace

import pytest

from emopose.contract import EventKind, GestureRecord
from emopose.execution.sequencer import State
from emopose.speech.clip import SpeechClip
from emopose.stages.dispatch import Dispatch
from emopose.stages.sequence import SequenceStage
from tests.stages.test_sequence import scheduled_turn
from tests.wiring import wire


class CountingPlayer:
    def __init__(self):
        self.played = []

    def play(self, clip, clock):
        self.played.append(clip.text)
        return clock.now()


def submitted_turn(run):
    run.session.open()
    turn = scheduled_turn(run)
    turn.submitted = run.stages[4](turn)
    return turn


@pytest.mark.parametrize("until, state", [("settle", State.HOLDING), ("rest", State.IDLE)])
def test_runs_the_loop_until_the_awaited_state(library, tmp_path, until, state):
    run = wire(library, tmp_path, record=False)
    player = CountingPlayer()
    turn = submitted_turn(run)
    report = Dispatch(run.loop, player, until=until)(turn)
    assert report.completed and run.sequencer.state == state
    assert player.played == [turn.speech.text]
    started = [e.name for e in report.events if e.kind == "started"]
    assert started == [g.name for g in turn.modulated]
    assert report.ticks == run.loop.stats.ticks > 0
    assert report.speech_start == turn.submitted.speech_start  # virtual time: no gap between the stages


def test_none_returns_at_once_and_a_timeout_is_reported(library, tmp_path):
    run = wire(library, tmp_path, record=False)
    turn = submitted_turn(run)
    assert Dispatch(run.loop, CountingPlayer(), until="none")(turn).ticks == 0
    late = Dispatch(run.loop, CountingPlayer(), timeout_s=0.1, until="rest")(turn)
    assert not late.completed and late.ticks == 5  # 0.1 s of 50 Hz ticks


def test_unknown_until_is_a_config_error(library, tmp_path):
    run = wire(library, tmp_path)
    with pytest.raises(ValueError, match="until must be one of"):
        Dispatch(run.loop, run.player, until="forever")


def test_gestures_follow_the_audio_when_it_starts_later_than_planned(library, tmp_path):
    class LateDevice(CountingPlayer):
        def play(self, clip, clock):
            super().play(clip, clock)
            return clock.now() + 0.13  # launch plus an output latency the plan did not know

    run = wire(library, tmp_path, record=False)
    turn = submitted_turn(run)
    planned = [c.release_at for c in turn.submitted.commands]
    report = Dispatch(run.loop, LateDevice(), until="settle")(turn)
    started = {e.command_id: e.t for e in report.events if e.kind == "started"}
    assert report.speech_start == turn.submitted.speech_start + 0.13
    first, second = turn.submitted.commands
    assert 0 <= started[first.id] - (planned[0] + 0.13) <= 0.02 + 1e-9  # within one tick of the shift
    assert started[second.id] >= planned[1] + 0.13  # never before its word as heard (it may queue)


def dropped_gesture_turn(run, reply):
    """A turn whose schedule dropped its one gesture (as a named gesture that does not fit is)."""
    turn = scheduled_turn(run, reply, (GestureRecord(cls="rejecting", trigger=reply or None),))
    turn.speech = SpeechClip(text=reply, duration_s=0.4 * len(reply.split()))
    releases = tuple(replace(r, dropped="unsafe: test") for r in turn.schedule.releases)
    turn.schedule = replace(turn.schedule, releases=releases)
    return turn


def test_a_turn_that_performs_nothing_leaves_the_running_one_alone(library, tmp_path):
    run = wire(library, tmp_path, record=False)
    running = submitted_turn(run)
    run.loop.run_until(lambda: run.sequencer.active is not None, 2.0)
    interrupting = SequenceStage(run.sequencer, run.loop.clock, run.player, interrupt=True)
    player = CountingPlayer()
    silent = dropped_gesture_turn(run, "")
    silent.submitted = interrupting(silent)
    report = Dispatch(run.loop, player, until="none")(silent)
    assert silent.submitted.commands == () and player.played == []
    assert run.sequencer.active.id == running.submitted.commands[0].id
    assert [e.kind for e in report.events] == []  # the drop was reported by the sequence stage
    spoken = dropped_gesture_turn(run, "No.")  # words to say: it replaces the running turn
    spoken.submitted = interrupting(spoken)
    Dispatch(run.loop, player, until="none")(spoken)
    assert player.played == ["No."] and run.sequencer.active is None
    stopped = [e for e in run.sequencer.events.since(0) if e.kind == EventKind.STOPPED]
    assert [e.command_id for e in stopped] == [running.submitted.commands[0].id]
