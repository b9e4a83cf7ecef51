"""Executed means executed (issue 28 item 5): with a backend that measures its joints, the STROKE event
comes from the measured arm, the command stream's arrival beside it as STROKE_COMMANDED."""

from __future__ import annotations

from collections import deque

import numpy as np
import pytest

from emopose.backends.dry_run import DryRunBackend
from emopose.execution.control_loop import ControlLoop
from tests.core.conftest import gesture
from tests.core.test_timeline_execution import Rig

DELAY_TICKS = 3


class LaggingArm(DryRunBackend):
    """Measures the command it was sent DELAY_TICKS periods ago (motors trailing their commands)."""

    measures_joints = True

    def __init__(self, rest: np.ndarray) -> None:
        super().__init__()
        self.history = deque([np.array(rest)] * DELAY_TICKS, maxlen=DELAY_TICKS + 1)

    def send(self, t, q):
        self.history.append(np.array(q))
        return super().send(t, q)

    def measured(self):
        return self.history[0]


class BlockedArm(DryRunBackend):
    """An arm that never leaves rest (held, or a law too weak): its strokes are never reached."""

    measures_joints = True

    def __init__(self, rest: np.ndarray) -> None:
        super().__init__()
        self.rest = np.array(rest)

    def measured(self):
        return self.rest


def measured_rig(library, backend_type) -> Rig:
    rig = Rig(library)
    rig.loop = ControlLoop(rig.sequencer, backend_type(rig.rest), rig.clock)
    rig.loop.begin(rig.rest)
    return rig


def strokes(rig: Rig, kind: str) -> list:
    return [e for e in rig.sequencer.events if e.kind == kind]


def test_the_stroke_event_waits_for_the_measured_arm(g1):
    rig = measured_rig(g1, LaggingArm)
    commands = rig.submit([gesture(g1, "point_left"), gesture(g1, "shrug")], [1.5, 4.0], 0.4)
    rig.run(6.0)
    commanded, measured = strokes(rig, "stroke_commanded"), strokes(rig, "stroke")
    assert [e.command_id for e in commanded] == [e.command_id for e in measured] == [c.id for c in commands]
    for early, late in zip(commanded, measured):
        # the lagging arm is where the command was DELAY_TICKS periods before
        assert late.t - early.t == pytest.approx(DELAY_TICKS * rig.loop.dt, abs=1e-9)
        assert late.detail == ""


def test_without_measured_joints_the_stroke_is_the_commands(g1):
    rig = Rig(g1)  # the dry run echoes its commands: nothing to measure
    rig.submit([gesture(g1, "point_left")], [1.5], 0.4)
    rig.run(4.0)
    assert len(strokes(rig, "stroke")) == 1 and not strokes(rig, "stroke_commanded")


def test_a_stroke_the_arm_never_reaches_is_reported_as_not_reached(g1):
    rig = measured_rig(g1, BlockedArm)
    rig.submit([gesture(g1, "point_left")], [1.5], 0.4)
    rig.run(4.0)
    (commanded,), (measured,) = strokes(rig, "stroke_commanded"), strokes(rig, "stroke")
    expire_s = rig.sequencer.stroke_watch.expire_s
    assert measured.t - commanded.t == pytest.approx(expire_s, abs=rig.loop.dt)
    assert measured.detail.startswith("not reached: closest")
