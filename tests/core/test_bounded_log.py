"""Long-running servers keep bounded event logs: readers with a cursor neither miss nor repeat entries."""

from __future__ import annotations

import numpy as np

from emopose.execution.bounded_log import BoundedLog
from emopose.execution.gesture_command import GestureCommand
from emopose.execution.sequencer import Sequencer
from emopose.execution.trajectory import TrajectoryBuilder


def test_the_event_log_stays_bounded_and_cursors_still_work(g1):
    sequencer = Sequencer(TrajectoryBuilder(g1.limits), g1.neutral_entry.q[0], keep_events=5)
    cursor = sequencer.events.total
    for k in range(12):
        sequencer.drop(GestureCommand(f"g{k}", np.zeros((1, 14)), 1.0), "test", float(k))
    assert len(sequencer.events) == 5 and sequencer.events.total == cursor + 12
    assert [e.name for e in sequencer.events.since(cursor + 9)] == ["g9", "g10", "g11"]
    assert [e.name for e in sequencer.events.since(cursor)] == [f"g{k}" for k in range(7, 12)]


def test_a_reader_behind_the_window_resumes_at_the_newest_entry_without_repeats():
    log = BoundedLog(keep=3)
    for k in range(10):
        log.append(k)
    entries, cursor = log.read(2)  # entries 2..6 fell out of the window
    assert entries == [7, 8, 9] and cursor == 10
    log.append(10)
    assert log.read(cursor) == ([10], 11)
