"""Every sequencer transition with a fake clock, plus continuity and thread safety."""

import json
import threading

import numpy as np
import pytest

from emopose.backends.dry_run import DryRunBackend
from emopose.clock import FakeClock
from emopose.execution.control_loop import ControlLoop
from emopose.execution.gesture_command import EventKind, GestureCommand
from emopose.execution.sequencer import Sequencer, State
from emopose.execution.trajectory import TrajectoryBuilder
from emopose.sync.recording import event_message


def command(library, name, release_at=float("-inf")):
    entry = library.get(name)
    return GestureCommand(name, entry.q, entry.default_duration, release_at, entry.cls)


@pytest.fixture
def rig(library, rest):
    clock = FakeClock()
    sequencer = Sequencer(TrajectoryBuilder(library.limits), rest)
    loop = ControlLoop(sequencer, DryRunBackend(), clock)
    loop.begin(rest)
    stream = []
    original = loop.tick

    def tick():
        q = original()
        stream.append((clock.now(), sequencer.state, q))
        return q

    loop.tick = tick
    return sequencer, loop, clock, stream


def kinds(sequencer, kind):
    return [e for e in sequencer.events if e.kind == kind]


def assert_continuous(stream, library):
    q = np.array([s[2] for s in stream])
    steps = np.abs(np.diff(q, axis=0))
    assert np.all(steps <= library.limits.max_velocity * 0.02 + 1e-9)


def test_idle_to_executing_to_holding_then_neutral(library, rig, rest):
    sequencer, loop, clock, stream = rig
    ends_raised = np.vstack([rest, rest + 0.3, rest + 0.2])  # a non-neutral endpoint
    sequencer.submit(GestureCommand("ends_raised", ends_raised, 1.0))
    loop.tick()
    assert sequencer.state == State.EXECUTING
    loop.run_until(lambda: sequencer.state == State.HOLDING, 10)
    held_at = clock.now()
    loop.run_until(lambda: sequencer.state == State.IDLE, 10)
    states = [s[1] for s in stream]
    assert State.BLENDING in states[states.index(State.HOLDING):]
    recovery_start = next(e.t for e in sequencer.events
                          if e.kind == EventKind.STATE and e.detail == State.BLENDING)
    assert recovery_start - held_at == pytest.approx(2.0, abs=0.021)  # hold 2 s
    assert clock.now() - recovery_start == pytest.approx(1.0, abs=0.021)  # neutral in 1 s
    assert np.allclose(sequencer.last, library.neutral_entry.q[0])
    assert_continuous(stream, library)


def test_neutral_endpoint_goes_idle_without_blend(library, rig):
    sequencer, loop, clock, stream = rig
    sequencer.submit(command(library, "agreeing_a"))
    loop.run_until(lambda: sequencer.state == State.IDLE, 10)
    states = [s[1] for s in stream]
    assert State.BLENDING not in states[states.index(State.HOLDING):]


def test_queue_order_and_blend_at_most_03s(library, rig):
    sequencer, loop, clock, stream = rig
    for name in ("welcoming_a", "pointing_b", "rejecting_a"):
        sequencer.submit(command(library, name))
    loop.run_until(sequencer.settled, 30)
    started = [e.name for e in kinds(sequencer, EventKind.STARTED)]
    assert started == ["welcoming_a", "pointing_b", "rejecting_a"]
    blends = []
    for (t0, s0, _), (t1, s1, _) in zip(stream, stream[1:]):
        if s1 == State.BLENDING and s0 != State.BLENDING:
            blends.append([t1, None])
        if s0 == State.BLENDING and s1 != State.BLENDING:
            blends[-1][1] = t0
    assert len(blends) == 2 and all(end - start <= 0.3 + 1e-9 for start, end in blends)
    assert_continuous(stream, library)


def test_release_time_is_respected(library, rig):
    sequencer, loop, clock, stream = rig
    sequencer.submit(command(library, "pointing_a", release_at=clock.now() + 0.5))
    loop.run_until(lambda: bool(kinds(sequencer, EventKind.STARTED)), 5)
    assert kinds(sequencer, EventKind.STARTED)[0].t == pytest.approx(0.5, abs=0.02)


def test_holding_accepts_new_command_directly(library, rig):
    sequencer, loop, clock, stream = rig
    sequencer.submit(command(library, "agreeing_b"))
    loop.run_until(lambda: sequencer.state == State.HOLDING, 10)
    loop.tick()
    sequencer.submit(command(library, "doubting_b"))
    loop.tick()
    assert sequencer.state == State.EXECUTING and sequencer.active.name == "doubting_b"
    assert_continuous(stream, library)


def test_interrupt_clears_queue_and_blends_from_latest(library, rig):
    sequencer, loop, clock, stream = rig
    for name in ("welcoming_a", "pointing_a", "rejecting_a"):
        sequencer.submit(command(library, name))
    for _ in range(20):
        loop.tick()
    before = sequencer.last.copy()
    sequencer.interrupt([command(library, "comforting_b")], now=clock.now())
    assert sequencer.pending == [] and sequencer.state == State.BLENDING
    assert kinds(sequencer, EventKind.STOPPED)[0].name == "welcoming_a"
    loop.tick()
    assert np.max(np.abs(sequencer.last - before)) <= library.limits.max_velocity.max() * 0.02
    loop.run_until(sequencer.settled, 10)
    assert [e.name for e in kinds(sequencer, EventKind.STARTED)] == ["welcoming_a", "comforting_b"]
    assert_continuous(stream, library)


def test_interrupt_during_blend_and_without_target(library, rig):
    sequencer, loop, clock, stream = rig
    sequencer.submit(command(library, "welcoming_a"))
    sequencer.submit(command(library, "pointing_a"))
    loop.run_until(lambda: sequencer.state == State.BLENDING, 10)
    loop.tick()
    sequencer.interrupt([], now=clock.now())
    loop.run_until(lambda: sequencer.state == State.IDLE, 10)
    assert np.allclose(sequencer.last, library.neutral_entry.q[0])
    assert_continuous(stream, library)


def test_unsafe_candidate_rejected_with_reason(library, rest):
    sequencer = Sequencer(TrajectoryBuilder(library.limits), rest, safety=lambda s: "hand inside torso")
    sequencer.submit(command(library, "pointing_a"))
    sequencer.step(0.0)
    assert sequencer.state == State.IDLE
    last = sequencer.events.recent(1)[0]
    assert last.kind == EventKind.REJECTED and "torso" in last.detail


def test_submit_and_interrupt_are_thread_safe(library, rig):
    sequencer, loop, clock, stream = rig
    loop.start()
    stop = threading.Event()

    def spam():
        while not stop.is_set():
            sequencer.submit(command(library, "emphasizing_b"))
            sequencer.interrupt([command(library, "agreeing_b")], now=clock.now())

    workers = [threading.Thread(target=spam) for _ in range(3)]
    for w in workers:
        w.start()
    threading.Event().wait(0.3)
    stop.set()
    for w in workers:
        w.join()
    loop.stop()
    assert loop.error is None and loop.stats.ticks > 10
    assert_continuous(stream, library)


def test_overdue_successor_preempts_only_when_enabled(library, rest):
    for preempt, expect_stop in ((None, False), (0.1, True)):
        clock = FakeClock()
        sequencer = Sequencer(TrajectoryBuilder(library.limits), rest, preempt_after_s=preempt)
        loop = ControlLoop(sequencer, DryRunBackend(), clock)
        loop.begin(rest)
        sequencer.submit(command(library, "pointing_a"))  # 1 s long
        sequencer.submit(command(library, "welcoming_b", release_at=0.3))
        loop.run_until(sequencer.settled, 10)
        started = {e.name: e.t for e in kinds(sequencer, EventKind.STARTED)}
        assert bool(kinds(sequencer, EventKind.STOPPED)) == expect_stop
        if expect_stop:
            assert started["welcoming_b"] <= 0.3 + 0.1 + 0.3 + 0.02  # overdue by 0.1 s, then a <= 0.3 s blend
        else:
            assert started["welcoming_b"] >= 1.0


def test_event_kinds_are_enums_and_recorded_as_their_strings(library, rig):
    sequencer, loop, _, _ = rig
    sequencer.submit(command(library, "welcoming_a"))
    loop.run_until(lambda: sequencer.state == State.IDLE and bool(kinds(sequencer, EventKind.COMPLETED)), 20)
    assert {type(e.kind) for e in sequencer.events} == {EventKind}
    assert [e.kind for e in sequencer.events if e.kind != EventKind.STATE] == [
        EventKind.STARTED, EventKind.COMPLETED]
    recorded = json.dumps(event_message(kinds(sequencer, EventKind.STARTED)[0], 0.0))  # as in session.mcap
    assert json.loads(recorded)["kind"] == "started" and type(json.loads(recorded)["kind"]) is str
