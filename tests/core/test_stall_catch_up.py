"""Stalls in virtual time (the loop does not tick for 50-400 ms, the clock runs on): a running gesture
catches up to its planned keyframe times within the speed bound, or is stopped with the reason; one
command per tick, never a burst; later gestures keep their planned times."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from emopose.backends.dry_run import DryRunBackend
from emopose.execution.gesture_command import GestureCommand
from tests.core.conftest import gesture
from tests.core.test_timeline_execution import NAMES, Rig

ONSETS, SPEECH_START = [1.5, 4.0], 0.4


class StampingBackend(DryRunBackend):
    """Keeps each command with its stamp (the deadline it stands for) and the clock time it went out."""

    def __init__(self, clock) -> None:
        super().__init__()
        self.clock, self.commands = clock, []

    def send(self, t: float, q: np.ndarray) -> np.ndarray:
        self.commands.append((t, self.clock.now(), np.array(q)))
        return super().send(t, q)


def stalling_rig(g1) -> Rig:
    rig = Rig(g1)
    rig.loop.backend = StampingBackend(rig.clock)
    return rig


def run_with_stall(rig: Rig, stall_at: float, stall_s: float, then_s: float = 6.0) -> list[int]:
    """Tick until stall_at, let stall_s pass without a tick, tick on; the commands each tick sent."""
    sent = []
    for _ in range(round((stall_at - rig.clock.now()) / rig.loop.dt) + round(then_s / rig.loop.dt)):
        if stall_s and rig.clock.now() >= stall_at - 1e-9:
            rig.clock.advance(stall_s)
            stall_s = 0.0
        before = rig.loop.backend.sent
        rig.run(rig.loop.dt)
        sent.append(rig.loop.backend.sent - before)
    return sent


def stalled_timeline(g1, first: str, stall_s: float, stall_at=None, stop_late_s: float = 0.5):
    """`first` then a shrug on the timeline; the stall comes halfway through the first's preparation."""
    rig = stalling_rig(g1)
    rig.sequencer.stall_stop_late_s = stop_late_s
    lead, later = rig.submit([gesture(g1, first), gesture(g1, "shrug")], ONSETS, SPEECH_START)
    if stall_at is None:
        stall_at = lead.release_at + 0.5 * lead.offsets[lead.stroke[0]]
    sent = run_with_stall(rig, stall_at, stall_s)
    return rig, lead, later, sent


def event_time(rig: Rig, kind: str, command: GestureCommand) -> float | None:
    return next((e.t for e in rig.events(kind) if e.command_id == command.id), None)


def reached_at(rig: Rig, command: GestureCommand, key: int) -> np.ndarray:
    """The commanded pose on the first tick at or after keyframe `key`'s planned time."""
    planned = command.release_at + command.offsets[key]
    return next(q for t, q in rig.stream if t >= planned - 1e-9)


def command_speeds(rig: Rig) -> tuple[np.ndarray, np.ndarray]:
    """(stamps, joint speeds between consecutive commands on their stamps)."""
    stamps = np.array([c[0] for c in rig.loop.backend.commands])
    q = np.array([c[2] for c in rig.loop.backend.commands])
    return stamps, np.abs(np.diff(q, axis=0)) / np.diff(stamps)[:, None]


def assert_one_command_per_tick_within_the_bound(rig: Rig, sent: list[int], g1) -> None:
    assert set(sent) == {1}
    stamps, speed = command_speeds(rig)
    assert np.all(np.diff(stamps) >= rig.loop.dt - 1e-9)  # no burst after the stall
    went_out = np.array([c[1] for c in rig.loop.backend.commands])
    assert np.all(np.diff(went_out) >= rig.loop.dt / 2 - 1e-9)
    assert np.all(speed <= g1.limits.max_velocity + 1e-9)
    assert np.all(rig.steps() <= g1.limits.max_velocity * rig.loop.dt + 1e-9)  # and per tick


def peak_speed_share(rig: Rig, g1, after: float) -> float:
    """The fastest joint's speed, as a share of its bound, over the commands stamped after `after`."""
    stamps, speed = command_speeds(rig)
    return float((speed / g1.limits.max_velocity)[stamps[1:] > after].max())


@pytest.mark.parametrize("stall_s", [0.05, 0.15, 0.4])
def test_a_stall_mid_preparation_is_caught_up_and_the_stroke_keeps_its_time(g1, stall_s):
    calm, calm_lead, calm_later, _ = stalled_timeline(g1, "wave_off", 0.0)
    rig, lead, later, sent = stalled_timeline(g1, "wave_off", stall_s)
    key = lead.stroke[0]
    # the stroke keyframe is commanded on its planned tick, and the stroke is reported no later
    assert np.allclose(reached_at(rig, lead, key), lead.keyframes[key], atol=1e-9)
    assert event_time(rig, "stroke", lead) <= lead.release_at + lead.offsets[key] + rig.loop.dt
    assert event_time(rig, "stroke", lead) - event_time(calm, "stroke", calm_lead) < stall_s / 2
    # the later gesture keeps its planned start and stroke: the stall shifted nothing after it
    assert event_time(rig, "started", later) == pytest.approx(later.release_at, abs=rig.loop.dt)
    assert event_time(rig, "stroke", later) == pytest.approx(event_time(calm, "stroke", calm_later), abs=1e-9)
    assert not rig.events("stopped")
    assert_one_command_per_tick_within_the_bound(rig, sent, g1)


def test_a_stall_the_bound_cannot_absorb_makes_the_stroke_only_as_late_as_the_bound_forces(g1):
    calm, calm_lead, _, _ = stalled_timeline(g1, "palm_stop", 0.0)
    rig, lead, later, sent = stalled_timeline(g1, "palm_stop", 0.4)
    late = event_time(rig, "stroke", lead) - event_time(calm, "stroke", calm_lead)
    assert 0.0 < late < 0.4  # tick by tick it would be the whole stall
    stall_at = lead.release_at + 0.5 * lead.offsets[lead.stroke[0]]
    # it ran at the planning bound
    assert peak_speed_share(rig, g1, stall_at) == pytest.approx(g1.limits.speed_fraction, abs=0.02)
    assert event_time(rig, "started", later) == pytest.approx(later.release_at, abs=rig.loop.dt)
    assert_one_command_per_tick_within_the_bound(rig, sent, g1)


def test_a_gesture_whose_stroke_would_come_too_late_is_stopped_with_the_reason(g1):
    rig, lead, later, sent = stalled_timeline(g1, "palm_stop", 0.4, stop_late_s=0.2)
    (stopped,) = rig.events("stopped")
    assert stopped.command_id == lead.id and stopped.detail.startswith("stall: stroke")
    assert int(stopped.detail.split()[2]) > 200
    assert event_time(rig, "stroke", lead) is None
    assert event_time(rig, "started", later) == pytest.approx(later.release_at, abs=rig.loop.dt)
    assert event_time(rig, "stroke", later) is not None
    assert_one_command_per_tick_within_the_bound(rig, sent, g1)


@pytest.mark.parametrize("stall_s", [0.05, 0.15])
def test_a_stall_during_the_stroke_keeps_the_later_keyframes_on_their_times(g1, stall_s):
    _, lead, _, _ = stalled_timeline(g1, "wave_off", 0.0)
    first, last = lead.stroke[0], len(lead.offsets) - 1
    stall_at = lead.release_at + (lead.offsets[first] + lead.offsets[first + 1]) / 2
    rig, lead, later, sent = stalled_timeline(g1, "wave_off", stall_s, stall_at)
    for key in range(first + 1, last + 1):
        assert np.allclose(reached_at(rig, lead, key), lead.keyframes[key], atol=1e-9)
    assert len([e for e in rig.events("stroke") if e.command_id == lead.id]) == 1
    assert event_time(rig, "started", later) == pytest.approx(later.release_at, abs=rig.loop.dt)
    assert_one_command_per_tick_within_the_bound(rig, sent, g1)


def test_a_queued_motion_catches_up_too(g1):
    """The paper's FIFO modes: a released (untimed) motion still ends on its planned time after a stall."""
    entry = g1.get("wave_off")
    ends = {}
    for stall_s in (0.0, 0.15):
        rig = stalling_rig(g1)
        rig.sequencer.submit(GestureCommand("wave_off", entry.q, entry.default_duration, release_at=0.2))
        sent = run_with_stall(rig, 0.2 + entry.default_duration / 3, stall_s)
        ends[stall_s] = next(e.t for e in rig.sequencer.events if e.kind in ("completed", "cut"))
        assert_one_command_per_tick_within_the_bound(rig, sent, g1)
    assert ends[0.15] == pytest.approx(ends[0.0], abs=1e-9)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(picks=st.lists(st.tuples(st.sampled_from(NAMES), st.integers(1, 5), st.floats(0.0, 6.0)), min_size=1,
                      max_size=4),
       stall_at=st.floats(0.1, 6.0), stall_s=st.floats(0.03, 0.45))
def test_random_timelines_with_a_stall_stay_within_the_bound_and_keep_later_starts(g1, picks, stall_at,
                                                                                  stall_s):
    rig = stalling_rig(g1)
    commands = rig.submit([gesture(g1, name, level) for name, level, _ in picks],
                          [onset for *_, onset in picks], SPEECH_START)
    sent = run_with_stall(rig, stall_at, stall_s, then_s=10.0)
    assert_one_command_per_tick_within_the_bound(rig, sent, g1)
    stall_end = stall_at + stall_s + rig.loop.dt
    for command in commands:
        started = event_time(rig, "started", command)
        if command.release_at > stall_end and started is not None:
            assert started == pytest.approx(command.release_at, abs=rig.loop.dt + 1e-9)
