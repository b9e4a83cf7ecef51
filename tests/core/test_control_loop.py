"""The control loop's pacing on a virtual clock: a stall or idle time is skipped and counted, never
sent as a burst; no two commands closer than half a period; lateness kept in a bounded window."""

from __future__ import annotations

import gc
import sys
import threading

import numpy as np
import pytest

from emopose import CONTROL_DT
from emopose.backends.dry_run import DryRunBackend
from emopose.build import ConfigError, build_job
from emopose.clock import FakeClock
from emopose.execution import control_loop
from emopose.execution.control_loop import ControlLoop, LoopStats
from emopose.execution.sequencer import Sequencer
from emopose.execution.trajectory import TrajectoryBuilder
from emopose.recording import Recorder, read_recording


class SleepyClock(FakeClock):
    """Virtual time whose n-th sleep overshoots by oversleep[n] (the loop thread was descheduled)."""

    def __init__(self, oversleep: dict[int, float]) -> None:
        super().__init__()
        self.oversleep, self.sleeps = oversleep, 0

    def sleep_until(self, deadline: float) -> None:
        self.sleeps += 1
        super().sleep_until(deadline)
        self.advance(self.oversleep.get(self.sleeps, 0.0))


class TimedBackend(DryRunBackend):
    """Records the virtual time of every send; the send numbered in `slow` blocks that long."""

    def __init__(self, clock: FakeClock, slow: dict[int, float]) -> None:
        super().__init__()
        self.clock, self.slow, self.sent_at = clock, slow, []

    def send(self, t: float, q: np.ndarray) -> None:
        self.sent_at.append(self.clock.now())
        self.clock.advance(self.slow.get(len(self.sent_at), 0.0))
        return super().send(t, q)


@pytest.fixture
def make_loop(library, rest):
    def make(oversleep=None, slow=None) -> tuple[ControlLoop, TimedBackend, FakeClock]:
        clock = SleepyClock(oversleep or {})
        backend = TimedBackend(clock, slow or {})
        loop = ControlLoop(Sequencer(TrajectoryBuilder(library.limits), rest), backend, clock)
        loop.begin(rest)
        return loop, backend, clock

    return make


def sends_within(sent_at: list[float], start: float, seconds: float) -> int:
    return sum(start <= t < start + seconds for t in sent_at)


@pytest.mark.parametrize("where", ["oversleep", "slow"])
def test_a_stall_is_skipped_and_counted_not_burst(make_loop, where):
    loop, backend, _ = make_loop(**{where: {5: 2.9}})  # the 5th tick stalls 2.9 s (asleep, or in send)
    loop.run_until(lambda: False, 4.0)
    sent = np.array(backend.sent_at)
    resumed = sent[4] if where == "oversleep" else sent[4] + 2.9  # when the stalled tick ended
    assert resumed == pytest.approx(3.0)
    assert sends_within(backend.sent_at, resumed, 0.25) <= 13  # 50 Hz; the old loop sent 146 here
    assert np.diff(sent).min() >= CONTROL_DT / 2 - 1e-9
    assert np.allclose(np.diff(sent[5:]), CONTROL_DT)  # back on the 50 Hz grid at once
    assert loop.stats.stalls == 1 and loop.stats.missed_deadlines == 145  # 0.12 .. 3.0 s: covered
    assert loop.stats.ticks == len(sent) and loop.stats.idle_ticks == 0


def test_idle_time_before_the_first_tick_is_not_a_burst_nor_a_miss(make_loop):
    loop, backend, clock = make_loop()
    clock.advance(2.9)  # the planner thinks after the session opened; nobody ticks
    loop.run_until(lambda: False, 1.0)
    assert backend.sent_at[0] == pytest.approx(2.9)
    assert sends_within(backend.sent_at, 2.9, 0.25) <= 13
    assert np.allclose(np.diff(backend.sent_at), CONTROL_DT)
    assert loop.stats.missed_deadlines == 0 and loop.stats.stalls == 0
    assert loop.stats.idle_ticks == 144


def test_a_late_tick_pushes_the_next_one_to_half_a_period(make_loop):
    loop, backend, _ = make_loop(oversleep={3: 0.9 * CONTROL_DT})  # late, but by less than a period
    loop.run_until(lambda: False, 0.2)
    gaps = np.diff(backend.sent_at)
    assert gaps.min() == pytest.approx(CONTROL_DT / 2)  # not the 0.1 period the deadline would give
    assert loop.stats.missed_deadlines == 0  # nothing skipped: the grid keeps its phase
    assert backend.sent_at[-1] == pytest.approx(round(backend.sent_at[-1] / CONTROL_DT) * CONTROL_DT)


def test_lateness_is_a_bounded_window_with_run_counters():
    stats = LoopStats(window=50)
    for k in range(200):
        stats.add(0.001 * (k % 7) + (0.5 if k == 3 else 0.0))
    assert stats.ticks == 200 and len(stats.lateness_s) == 50
    summary = stats.summary()
    assert summary["lateness_ms_max"] == pytest.approx(503.0)  # the run's worst, though out of the window
    assert summary["lateness_ms_p99"] < 10.0


def test_a_long_run_keeps_the_window_bounded(make_loop):
    loop, _, _ = make_loop()
    loop.run_until(lambda: False, 2 * loop.stats.window * CONTROL_DT)
    assert loop.stats.ticks >= 2 * loop.stats.window - 1
    assert len(loop.stats.lateness_s) == loop.stats.window


class ClampingBackend(DryRunBackend):
    """Sends at most `ceiling` on every joint, as a backend clamps to its limits."""

    def __init__(self, ceiling: float) -> None:
        super().__init__()
        self.ceiling = ceiling

    def send(self, t: float, q: np.ndarray) -> np.ndarray:
        return super().send(t, np.minimum(q, self.ceiling))


def test_the_loop_records_what_the_backend_sent_not_what_was_asked(library, rest, tmp_path):
    clock = FakeClock()
    sequencer = Sequencer(TrajectoryBuilder(library.limits), rest)
    ceiling = float(np.max(rest)) - 0.1  # below the rest pose on at least one joint
    loop = ControlLoop(sequencer, ClampingBackend(ceiling), clock)
    with Recorder(tmp_path / "run.mcap", clock=clock) as recorder:
        loop.begin(rest, recorder)
        returned = loop.tick()
    assert np.max(returned) == pytest.approx(ceiling)
    commands = read_recording(tmp_path / "run.mcap")["/joints/command"]
    assert len(commands) == 1 and np.allclose(commands[0][1]["q"], returned)
    assert not np.allclose(commands[0][1]["q"], rest)  # the requested pose was not what went out


# -- the loop thread's priority: what the OS permits, and a clean fallback -----------------------------
@pytest.mark.parametrize("priority, expected", [(10, "SCHED_FIFO 10; process nice -5"), (0, "normal")])
def test_start_raises_the_thread_and_shortens_the_switch_interval_until_stop(make_loop, monkeypatch,
                                                                             priority, expected):
    """On the loop's own thread, only when asked; stop() gives the process its switch interval back."""
    asked_from = []
    monkeypatch.setattr(control_loop, "raise_thread_priority",
                        lambda p: asked_from.append(threading.current_thread().name) or f"SCHED_FIFO {p}")
    monkeypatch.setattr(control_loop, "raise_process_priority", lambda: "process nice -5")
    loop, _, _ = make_loop()
    before = sys.getswitchinterval()
    loop.start(priority)
    try:
        assert sys.getswitchinterval() == (control_loop.RT_SWITCH_INTERVAL_S if priority else before)
    finally:
        loop.stop()
    assert sys.getswitchinterval() == before
    assert asked_from == (["emopose-control"] if priority else [])
    assert loop.stats.scheduling == loop.stats.summary()["scheduling"] == expected


def test_a_real_time_start_freezes_what_set_up_left_and_times_every_collection(make_loop, monkeypatch):
    """A full collection over a served process's 70,000+ set-up objects took 143 ms: a gap in the stream.
    Real-time runs exempt them (gc.freeze) and show the collector's pauses in loop health."""
    monkeypatch.setattr(control_loop, "raise_thread_priority", lambda p: f"SCHED_FIFO {p}")
    monkeypatch.setattr(control_loop, "raise_process_priority", lambda: "process nice -5")
    froze: list[int] = []
    freeze = control_loop.freeze_survivors
    monkeypatch.setattr(control_loop, "freeze_survivors", lambda: froze.append(1) or freeze())
    loop, _, _ = make_loop()
    loop.start(0)
    loop.stop()
    assert froze == [] and loop.stats.summary()["gc_collections"] == 0  # not real time: left alone
    loop, _, _ = make_loop()
    loop.start(10)
    try:
        assert froze == [1] and gc.get_freeze_count() > 10_000  # the test process's set-up objects
        gc.collect()
        summary = loop.stats.summary()
        assert summary["gc_full_collections"] >= 1 and summary["gc_pause_ms_max"] > 0
    finally:
        loop.stop()
    counted = loop.stats.summary()["gc_collections"]
    gc.collect()
    assert loop.stats.summary()["gc_collections"] == counted  # stop() took the timer out


def test_the_summary_reports_misses_per_tick():
    stats = LoopStats(ticks=400, missed_deadlines=6, stalls=2)
    summary = stats.summary()
    assert summary["missed_per_tick"] == pytest.approx(0.015)
    assert summary["missed_deadlines"] == 6 and summary["stalls"] == 2


@pytest.mark.parametrize("experiment", ["serve", "tour_lab"])
@pytest.mark.parametrize("priority", [-1, 100, 500])
def test_an_impossible_loop_priority_is_a_config_error(compose, experiment, priority):
    with pytest.raises(ConfigError, match=r"run.rt_priority=.*1-99"):
        build_job(compose(f"+experiment={experiment}", f"run.rt_priority={priority}"))


def test_the_tour_takes_the_loop_priority(compose):
    assert build_job(compose("+experiment=tour_lab", "run.rt_priority=7")).rt_priority == 7
