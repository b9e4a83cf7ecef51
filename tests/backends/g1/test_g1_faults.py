"""Safety behaviour against the fake G1 over real DDS: refusal to start, CRC checks, lost
state and a stalled sequencer both releasing the arms within their bounds."""

from __future__ import annotations

import time

import numpy as np
import pytest

from emopose.backends.g1 import G1Backend, G1BackendError, G1ConnectionError
from emopose.clock import MonotonicClock
from emopose.recording import Recorder, read_recording

FAST = {
    "lowstate_timeout_s": 10.0,
    "weight_ramp_up_s": 0.2,
    "weight_ramp_down_s": 0.4,
    "release_blend_s": 0.2,
}


def stream(backend: G1Backend, q0: np.ndarray, ticks: int, start_t: float = 0.0) -> None:
    clock = MonotonicClock()
    deadline = clock.now()
    for i in range(ticks):
        deadline += 0.02
        clock.sleep_until(deadline)
        backend.send(start_t + i * 0.02, q0 + 0.05 * np.sin(i / 5))


def wait_until(predicate, timeout_s: float) -> float:
    """Poll every ms; return the time it became true (perf_counter), or fail."""
    deadline = time.perf_counter() + timeout_s
    while time.perf_counter() < deadline:
        if predicate():
            return time.perf_counter()
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


@pytest.mark.slow
def test_lowstate_loss_releases_within_the_bound(fake_robot, domain_id, tmp_path):
    robot = fake_robot()
    recorder = Recorder(tmp_path / "loss.mcap")
    backend = G1Backend(domain_id=domain_id, lowstate_loss_ms=200, **FAST)
    q0 = backend.connect(recorder)
    stream(backend, q0, 10)
    robot.kill()
    killed = time.perf_counter()
    clock, deadline, i = MonotonicClock(), MonotonicClock().now(), 0
    with pytest.raises(G1BackendError, match="lost rt/lowstate"):
        while True:  # the sequencer keeps going: only the state loss can trip the release
            deadline += 0.02
            clock.sleep_until(deadline)
            backend.send(1.0 + i * 0.02, q0)
            i += 1
    detected = wait_until(lambda: backend.failure is not None, 1.0)
    assert 0.15 <= detected - killed <= 0.2 + 0.15, (
        f"released {detected - killed:.3f} s after the loss"
    )
    wait_until(lambda: backend.state == "failed", 2.0)
    backend.close()
    backend.close()
    recorder.close()
    rec = read_recording(tmp_path / "loss.mcap")
    assert "lost rt/lowstate" in rec["/g1/event"][0][1]["reason"]
    release = [p for _, p in rec["/g1/lowcmd"] if p["phase"] == "release"]
    weights = [p["weight"] for p in release]
    assert weights[-1] == 0.0 and np.all(np.diff(weights) <= 0)


@pytest.mark.slow
def test_stalled_sequencer_trips_the_deadman(fake_robot, domain_id):
    robot = fake_robot()
    neutral = [0.0] * 14
    backend = G1Backend(domain_id=domain_id, deadman_ms=100, neutral_pose=neutral, **FAST)
    q0 = backend.connect(None)
    time.sleep(0.3)  # before the first send() the backend holds the pose itself: no deadman yet
    assert backend.state == "holding" and backend.failure is None
    stream(backend, q0, 10)
    stalled = time.perf_counter()
    detected = wait_until(lambda: backend.failure is not None, 1.0)
    assert 0.1 <= detected - stalled <= 0.1 + 0.1 and "deadman" in backend.failure
    with pytest.raises(G1BackendError, match="deadman"):
        backend.send(5.0, q0)
    wait_until(lambda: backend.state == "failed", 2.0)
    backend.close()
    arm = robot.wait_for("arm", 10 + 10 + 10 + 20 + 1)
    holds = [a for a in arm if a["weight"] == 1.0 and np.allclose(a["q"], np.float32(q0))]
    assert len(holds) >= 10  # ~15 hold ticks during the 0.3 s wait
    release = arm[-(10 + 20) :]  # 0.2 s blend + 0.4 s ramp down, 50 Hz
    weights = np.array([a["weight"] for a in release])
    assert np.all(weights[:10] == 1.0) and np.all(np.diff(weights) <= 0) and weights[-1] == 0.0
    assert np.allclose(release[-1]["q"], neutral) and all(a["crc_ok"] for a in arm)
    time.sleep(0.1)
    assert len(robot.entries("arm")) == len(arm)  # and then it stops publishing
