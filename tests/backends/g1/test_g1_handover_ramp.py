"""The weight ramp-up against the fake G1: a configured ramp too short for the per-tick bound on the
feed-forwards (MAX_EFFORT_STEP_NM) is stretched to what the bound needs, and says so once."""

from __future__ import annotations

import logging

import numpy as np
import pytest

from emopose.backends.g1 import G1Backend
from emopose.backends.g1.handover import ramp_up_ticks
from emopose.backends.g1.release import MAX_EFFORT_STEP_NM
from emopose.clock import FakeClock
from emopose.recording import Recorder, read_recording

KD = 1.5
SHORT = {"lowstate_timeout_s": 10.0, "weight_ramp_up_s": 0.02, "weight_ramp_down_s": 0.4,
         "release_blend_s": 0.2, "lowstate_loss_ms": 60_000, "deadman_ms": 5_000, "kp": 60.0, "kd": KD,
         "velocity_feedforward": True, "gravity_compensation": True}
ARMS_FORWARD = [-1.2, 0.3, 0.0, 0.0, 0.0, 0.0, 0.0, -1.2, -0.3, 0.0, 0.0, 0.0, 0.0, 0.0]


def test_the_configured_length_stands_where_the_bound_allows_it():
    assert ramp_up_ticks(1.0, 6.3) == 50  # the 1 s default: 6.3 sin(pi / 100) = 0.2 N m a tick
    assert ramp_up_ticks(0.02, MAX_EFFORT_STEP_NM) == 1  # nothing to ramp beyond the bound
    n = ramp_up_ticks(0.02, 6.0)
    assert 6.0 * np.sin(np.pi / (2 * n)) <= MAX_EFFORT_STEP_NM < 6.0 * np.sin(np.pi / (2 * (n - 1)))


@pytest.mark.slow  # a fake robot process
def test_a_short_ramp_up_is_stretched_to_the_effort_bound(fake_robot, domain_id, tmp_path, caplog):
    fake_robot(f"--arm-pose={','.join(map(str, ARMS_FORWARD))}")  # one argument, though it starts with "-"
    clock = FakeClock()
    recorder = Recorder(tmp_path / "run.mcap", clock=clock)
    backend = G1Backend(domain_id=domain_id, clock=clock, **SHORT)
    with caplog.at_level(logging.WARNING, logger="emopose.backends.g1.handover"):
        backend.connect(recorder)
    backend.close()
    recorder.close()
    sent = [p for _, p in read_recording(tmp_path / "run.mcap")["/g1/lowcmd"] if p["phase"] == "ramp_up"]
    effort = np.array([KD * np.array(p["dq"]) + np.array(p["tau"]) for p in sent])
    assert np.abs(effort[-1]).max() > 4.0  # a gravity torque worth ramping, at full weight
    assert sent[-1]["weight"] == 1.0 and len(sent) > 1  # before: one tick, 0.02 s
    steps = np.abs(np.diff(np.vstack([np.zeros(14), effort]), axis=0)).max()
    assert steps <= MAX_EFFORT_STEP_NM  # before: the whole G(hold), > 4 N m, in one tick
    stretched = [r for r in caplog.records if "stretched" in r.getMessage()]
    assert len(stretched) == 1 and "weight_ramp_up_s 0.02 s" in stretched[0].getMessage()
