"""What the G1's firmware sees of the 50 Hz stream when the planner thinks before the first tick:
no burst, and no two LowCmd_ closer than half a period (counted from the DDS source timestamps the
fake robot logs, so the receiver's batching cannot hide or invent a gap)."""

from __future__ import annotations

import time

import numpy as np
import pytest

from emopose.backends.g1 import G1Backend
from emopose.clock import MonotonicClock
from emopose.execution.control_loop import ControlLoop
from emopose.execution.sequencer import Sequencer
from emopose.execution.trajectory import TrajectoryBuilder
from emopose.recording import read_recording
from emopose.robot.g1_spec import CONTROL_DT
from emopose.turn.session import Session

pytestmark = pytest.mark.slow  # a real-time session: ramp, 1 s of thinking, 0.5 s of stream, release


def test_thinking_before_the_stream_is_no_burst(fake_robot, domain_id, library, rest, tmp_path):
    robot = fake_robot()
    clock = MonotonicClock()
    backend = G1Backend(domain_id=domain_id, lowstate_timeout_s=10.0, weight_ramp_up_s=0.2,
                        weight_ramp_down_s=0.2, release_blend_s=0.1, clock=clock)
    loop = ControlLoop(Sequencer(TrajectoryBuilder(library.limits), rest), backend, clock)
    with Session(backend, loop, rest, tmp_path) as session:
        session.open()
        time.sleep(1.0)  # the planner thinks; meanwhile the backend holds the pose at 50 Hz itself
        loop.run_until(lambda: False, 0.5)
    phases = [p["phase"] for _, p in read_recording(tmp_path / "session.mcap")["/g1/lowcmd"]]
    arm = robot.wait_for("arm", len(phases))
    assert len(arm) == len(phases)  # the fake heard every command, in order
    sent = np.array([a["sent_ns"] for a in arm]) / 1e9
    assert np.diff(sent).min() >= CONTROL_DT / 2 - 1e-4  # hold -> stream included
    stream = sent[[p == "stream" for p in phases]]
    assert np.sum(stream < stream[0] + 0.25) <= 14  # 50 Hz sends 13; before the fix ~50 went at once
    assert loop.stats.idle_ticks >= 40 and loop.stats.missed_deadlines <= loop.stats.ticks // 10
