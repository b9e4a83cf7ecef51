"""The thinking motion when the previous reply's gesture is still running as the planner starts (issue 31
item 7): it is queued the moment that gesture ends, while the plan is still pending, and dropped cleanly
when the plan arrives first. Virtual time: the test steps the sequencer itself on a FakeClock."""

from __future__ import annotations

from emopose.clock import FakeClock
from emopose.execution.gesture_command import GestureCommand, State
from emopose.execution.sequencer import Sequencer
from emopose.execution.trajectory import TrajectoryBuilder
from emopose.turn.thinking import THINKING_LABEL, ThinkingGesture

TICK = 0.02


def busy_robot(library):
    """A sequencer on a fake clock running the previous reply's gesture (comforting_a, ~1 s)."""
    clock = FakeClock()
    sequencer = Sequencer(TrajectoryBuilder(library.limits), library.neutral_entry.q[0])
    entry = library.get("comforting_a")
    sequencer.submit(GestureCommand(entry.name, entry.q, entry.default_duration, release_at=0.0))
    sequencer.step(clock.now())
    assert sequencer.active is not None and not sequencer.settled()
    return sequencer, clock


def step_until(sequencer, clock, done, limit_s: float = 20.0) -> None:
    while not done():
        assert clock.now() < limit_s, "never happened (virtual time)"
        clock.advance(TICK)
        sequencer.step(clock.now())


def events(sequencer, kind: str, name: str) -> list:
    return [e for e in sequencer.events if e.kind == kind and e.name == name]


def test_thinking_starts_when_the_previous_gesture_ends_while_the_plan_is_pending(library):
    sequencer, clock = busy_robot(library)
    thinking = ThinkingGesture(library, sequencer, clock, "doubting_a", repeats=2)
    with thinking.around_planning() as planning:
        assert planning.ids == set()  # the running gesture is never cut short for it
        step_until(sequencer, clock, sequencer.settled)  # the previous gesture completes: HOLDING
        ended = clock.now()
        assert planning.poll()  # queued now (or already, by the watcher: the same poll)
        assert [c.label for c in sequencer.pending] == [THINKING_LABEL] * 2
        step_until(sequencer, clock, lambda: events(sequencer, "started", "doubting_a"))
        started = events(sequencer, "started", "doubting_a")[0].t
        assert ended < started <= ended + TICK + 1e-9  # the robot did not stand still
        clock.advance(0.3)  # a slow plan: the thinking motion plays on
        sequencer.step(clock.now())
    assert len(events(sequencer, "completed", "comforting_a")) == 1  # not cut short
    assert len(events(sequencer, "stopped", "doubting_a")) == 1  # the plan arrived: thinking stops
    assert sequencer.pending == [] and sequencer.state == State.BLENDING


def test_a_plan_that_arrives_before_the_gesture_ends_queues_no_thinking(library):
    sequencer, clock = busy_robot(library)
    thinking = ThinkingGesture(library, sequencer, clock, "doubting_a", repeats=2)
    with thinking.around_planning() as planning:
        clock.advance(0.2)  # the plan comes back while the previous gesture still runs
        sequencer.step(clock.now())
    step_until(sequencer, clock, sequencer.settled)
    assert planning.poll()  # nothing left to wait for, and nothing queued by it
    planning.watcher.join(5)  # it stops polling once the plan is in
    assert not planning.watcher.is_alive()
    step_until(sequencer, clock, lambda: sequencer.state == State.IDLE)
    assert not events(sequencer, "started", "doubting_a") and sequencer.pending == []
    assert len(events(sequencer, "completed", "comforting_a")) == 1


def test_a_settled_robot_starts_thinking_at_once_without_a_watcher(library):
    clock = FakeClock()
    sequencer = Sequencer(TrajectoryBuilder(library.limits), library.neutral_entry.q[0])
    thinking = ThinkingGesture(library, sequencer, clock, "doubting_a", repeats=1)
    with thinking.around_planning() as planning:
        assert len(planning.ids) == 1 and planning.watcher is None
