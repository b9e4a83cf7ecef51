"""Safety behaviour against the fake G1 over real DDS: refusal to start, CRC checks, lost
state and a stalled sequencer both releasing the arms at their bounds.

The fault bounds are checked in the backend's virtual time (a FakeClock the test advances), so a
loaded machine cannot move them; benchmarks/g1_faults.py measures the same releases in wall time."""

from __future__ import annotations

import time

import numpy as np
import pytest

from emopose.backends.g1 import G1Backend, G1BackendError, G1ConnectionError
from emopose.clock import FakeClock
from emopose.recording import Recorder, read_recording

FAST = {
    "lowstate_timeout_s": 10.0,
    "weight_ramp_up_s": 0.2,
    "weight_ramp_down_s": 0.4,
    "release_blend_s": 0.2,
}


def wait_until(predicate, timeout_s: float) -> None:
    """Poll every ms until predicate() holds; fail after timeout_s (a generous wall-clock cap)."""
    deadline = time.perf_counter() + timeout_s
    while time.perf_counter() < deadline:
        if predicate():
            return
        time.sleep(0.001)
    raise AssertionError(f"condition not met within {timeout_s} s")


def test_refuses_to_start_without_lowstate(domain_id):
    pytest.importorskip(
        "cyclonedds.domain", reason="cyclonedds is not importable: run .ci/install_cyclonedds.sh"
    )
    backend = G1Backend(domain_id=domain_id, lowstate_timeout_s=0.5)
    with pytest.raises(G1ConnectionError) as err:
        backend.connect(None)
    message = str(err.value)
    assert (
        "rt/lowstate" in message
        and f"domain {domain_id}" in message
        and "interface Cyclone default" in message
    )
    assert backend.state == "closed"
    backend.close()
    backend.close()


def test_refuses_to_start_on_lowstate_with_bad_crc(fake_robot, domain_id):
    robot = fake_robot("--bad-lowstate-crc")
    backend = G1Backend(domain_id=domain_id, lowstate_timeout_s=1.0)
    with pytest.raises(G1ConnectionError, match=r"ignored [1-9]\d* with a bad CRC"):
        backend.connect(None)
    assert robot.entries("arm") == []  # not a single command went out


def test_fake_robot_ignores_commands_with_a_bad_crc(fake_robot, domain_id):
    from emopose.backends.g1.arm_command import ArmCommandBuilder
    from emopose.backends.g1.constants import TOPIC_ARM_SDK
    from emopose.backends.g1.dds import DdsSession
    from emopose.backends.g1.hg_types import LowCmd_
    from emopose.backends.g1.state_monitor import LowStateMonitor

    robot = fake_robot()
    session = DdsSession(domain_id, None)
    monitor = LowStateMonitor(session, time.perf_counter)
    monitor.start()
    try:
        writer = session.writer(TOPIC_ARM_SDK, LowCmd_)
        assert monitor.wait_first(5.0) and writer.matched.wait(5.0)
        time.sleep(0.3)  # our side matched; give the fake's reader time to match us back
        pose = monitor.arm_q()
        builder = ArmCommandBuilder(np.full(14, 60.0), np.full(14, 1.5))
        for _ in range(10):
            cdr, _crc = builder.build(pose + 0.5, 1.0)
            writer.write(
                cdr[:-1] + bytes([cdr[-1] ^ 0x01])
            )  # the crc is the last field: flip one bit
            time.sleep(0.02)
        time.sleep(0.2)
        assert np.array_equal(monitor.arm_q(), pose)  # the arm did not move at all
        rows = robot.wait_for("arm", 10)
        assert len(rows) == 10 and not any(r["crc_ok"] for r in rows)
        for _ in range(10):  # the same targets with the right CRC do move it
            writer.write(builder.build(pose + 0.5, 1.0)[0])
            time.sleep(0.02)
        time.sleep(0.3)
        assert np.abs(monitor.arm_q() - (pose + 0.5)).max() < 0.05
        assert sum(r["crc_ok"] for r in robot.wait_for("arm", 20)) == 10
    finally:
        monitor.stop()
        session.close()
    robot.stop()
    assert robot.entries("summary")[0]["bad_crc"] == 10


def advance(clock: FakeClock, seconds: float, settle_s: float = 0.05) -> None:
    """Move virtual time on, then give the supervisor (which polls every few ms) time to look."""
    clock.advance(seconds)
    time.sleep(settle_s)


@pytest.mark.slow
def test_lowstate_loss_releases_at_the_bound(fake_robot, domain_id, tmp_path):
    robot = fake_robot()
    recorder = Recorder(tmp_path / "loss.mcap")
    clock = FakeClock()  # the backend's virtual time: states are stamped with it, faults judged on it
    backend = G1Backend(domain_id=domain_id, lowstate_loss_ms=200, clock=clock,
                        **{**FAST, "weight_ramp_up_s": 0.02})  # one ramp tick: state stays fresh
    q0 = backend.connect(recorder)
    for i in range(10):
        clock.advance(0.02)
        backend.send(i * 0.02, q0)
    time.sleep(0.1)  # fresh states arrive, stamped with the current virtual time
    robot.kill()
    time.sleep(0.1)  # any in flight land too; from here the newest state is 0 ms old
    for i in range(9):  # the sequencer keeps going (no deadman): only the state loss can trip
        advance(clock, 0.02, settle_s=0.01)
        backend.send(1.0 + i * 0.02, q0)
    time.sleep(0.05)
    assert backend.failure is None  # 180 ms without state: inside the 200 ms bound
    advance(clock, 0.04)  # 220 ms
    wait_until(lambda: backend.failure is not None, 5.0)
    assert "no valid LowState_ for 220 ms (limit 200 ms" in backend.failure
    with pytest.raises(G1BackendError, match="lost rt/lowstate"):
        backend.send(2.0, q0)
    wait_until(lambda: backend.state == "failed", 5.0)
    backend.close()
    backend.close()
    recorder.close()
    rec = read_recording(tmp_path / "loss.mcap")
    assert "lost rt/lowstate" in rec["/g1/event"][0][1]["reason"]
    release = [p for _, p in rec["/g1/lowcmd"] if p["phase"] == "release"]
    weights = [p["weight"] for p in release]
    assert len(release) == 20  # the stream held the neutral pose, nothing to blend: the 0.4 s ramp down
    assert weights[-1] == 0.0 and np.all(np.diff(weights) <= 0)


@pytest.mark.slow
def test_stalled_sequencer_trips_the_deadman_at_the_bound(fake_robot, domain_id):
    robot = fake_robot()
    neutral = [0.0] * 14
    clock = FakeClock()
    backend = G1Backend(domain_id=domain_id, deadman_ms=100, lowstate_loss_ms=60_000,
                        neutral_pose=neutral, clock=clock, **FAST)
    q0 = backend.connect(None)
    ramp = len(robot.wait_for("arm", 10))
    for k in range(1, 16):  # before the first send() the backend holds the pose itself, one per tick
        clock.advance(0.02)
        assert len(robot.wait_for("arm", ramp + k)) == ramp + k
    assert backend.state == "holding" and backend.failure is None  # 300 ms idle: no deadman yet
    for i in range(10):
        clock.advance(0.02)
        backend.send(i * 0.02, q0)
    advance(clock, 0.09)
    assert backend.failure is None  # 90 ms since the last send(): inside the bound
    advance(clock, 0.02)
    wait_until(lambda: backend.failure is not None, 5.0)
    assert "deadman: send() not called for 110 ms (limit 100 ms)" in backend.failure
    with pytest.raises(G1BackendError, match="deadman"):
        backend.send(5.0, q0)
    wait_until(lambda: backend.state == "failed", 5.0)
    backend.close()
    arm = robot.wait_for("arm", ramp + 15 + 10 + 10 + 20)
    holds = [a for a in arm[ramp : ramp + 15] if a["weight"] == 1.0 and np.allclose(a["q"], np.float32(q0))]
    assert len(holds) == 15
    release = arm[-(10 + 20) :]  # 0.2 s blend + 0.4 s ramp down, 50 Hz
    weights = np.array([a["weight"] for a in release])
    assert np.all(weights[:10] == 1.0) and np.all(np.diff(weights) <= 0) and weights[-1] == 0.0
    assert np.allclose(release[-1]["q"], neutral) and all(a["crc_ok"] for a in arm)
    time.sleep(0.1)
    assert len(robot.entries("arm")) == len(arm)  # and then it stops publishing
