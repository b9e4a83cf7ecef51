"""One full session against the fake G1 over real DDS: connect, stream a trajectory, close.

The session runs once per module; each test checks one property of what the robot received.
"""

from __future__ import annotations

import numpy as np
import pytest

from emopose.backends.g1 import G1Backend, G1BackendError, profiles
from emopose.clock import MonotonicClock
from emopose.recording import Recorder, read_recording
from emopose.testing.fake_robot import DEFAULT_ARM_POSE

RAMP_UP_S, RAMP_DOWN_S, BLEND_S = 0.4, 0.6, 0.3
pytestmark = (
    pytest.mark.slow
)  # one ~5 s session (fake robot start, ramps, stream, release) per module
NEUTRAL = np.array([0.1, 0.1, 0.0, 0.5, 0.0, 0.0, 0.0, 0.1, -0.1, 0.0, 0.5, 0.0, 0.0, 0.0])
N = 60


def f32(x) -> np.ndarray:
    return np.asarray(x, dtype=np.float32).astype(float)


@pytest.fixture(scope="module")
def run(module_fake_robot, domain_id, tmp_path_factory):
    robot = module_fake_robot()
    path = tmp_path_factory.mktemp("rec") / "g1.mcap"
    recorder = Recorder(path)
    backend = G1Backend(
        domain_id=domain_id,
        lowstate_timeout_s=10.0,
        weight_ramp_up_s=RAMP_UP_S,
        weight_ramp_down_s=RAMP_DOWN_S,
        release_blend_s=BLEND_S,
        neutral_pose=NEUTRAL.tolist(),
    )
    q0 = backend.connect(recorder)
    connected = backend.is_connected
    k = np.arange(N)[:, None]
    traj = (
        q0[None, :]
        + 0.3 * np.sin(2 * np.pi * (k + 1) / (N + 1)) * np.linspace(0.5, 1.0, 14)[None, :]
    )
    traj[-1, 3] = 3.0  # beyond the elbow's upper limit 2.0944: must arrive clamped
    clock = MonotonicClock()
    deadline = clock.now()
    sent = []
    for i, q in enumerate(traj):
        deadline += 0.02
        clock.sleep_until(deadline)
        sent.append(backend.send(i * 0.02, q))
    measured = backend.measured()
    backend.close()
    before = len(robot.wait_for("arm", 10**6, timeout_s=0.5))  # let the release land
    backend.close()
    with pytest.raises(G1BackendError):
        backend.send(99.0, q0)
    expected = traj.copy()
    expected[-1, 3] = backend.settings.upper[3]
    total = len(robot.wait_for("arm", 10**6, timeout_s=0.5))  # anything the second close sent
    robot.stop()
    recorder.close()
    return {
        "q0": q0,
        "expected": expected,
        "arm": robot.entries("arm"),
        "measured": measured,
        "sent": np.array(sent),
        "connected": (connected, backend.is_connected),
        "second_close_sent": total - before,
        "recording": read_recording(path),
        "backend": backend,
    }


def test_send_returns_the_clamped_targets_and_is_connected_follows_the_session(run):
    np.testing.assert_allclose(run["sent"], run["expected"])  # the last one clamped at the elbow's limit
    assert run["connected"] == (True, False)


def test_connect_returns_the_measured_pose(run):
    assert np.allclose(run["q0"], f32(DEFAULT_ARM_POSE), atol=1e-6)


def test_robot_receives_exactly_the_trajectory_in_order(run):
    arm, expected = run["arm"], f32(run["expected"])
    received = np.array([a["q"] for a in arm])
    starts = [i for i in range(len(received)) if np.array_equal(received[i], expected[0])]
    assert starts, "first trajectory pose never arrived"
    got = received[starts[0] : starts[0] + N]
    assert got.shape == expected.shape
    for joint in range(14):
        assert np.array_equal(got[:, joint], expected[:, joint]), f"joint {joint} differs"
    assert all(a["crc_ok"] and a["weight"] == 1.0 for a in arm[starts[0] : starts[0] + N])


def test_every_command_is_valid_and_touches_only_the_arms(run):
    for a in run["arm"]:
        assert a["crc_ok"] and a["others_zero"]
        assert a["mode"] == [1] * 14 and a["waist_mode"] == [0, 0, 0]
        assert np.allclose(a["kp"], 60.0) and np.allclose(a["kd"], 1.5)


def test_weight_ramps_up_smoothly_from_zero(run):
    weights = np.array([a["weight"] for a in run["arm"]])
    first_full = int(np.argmax(weights == 1.0))
    up = np.concatenate([[0.0], weights[: first_full + 1]])
    assert np.all((up >= 0) & (up <= 1)) and np.all(np.diff(up) >= 0)
    assert np.diff(up).max() <= profiles.max_step(RAMP_UP_S, 0.02) + 1e-6
    assert first_full == round(RAMP_UP_S / 0.02) - 1  # every ramp tick arrived
    held = np.array([a["q"] for a in run["arm"][:first_full]])
    assert np.allclose(held, f32(run["q0"]))  # the measured pose is held while the weight rises


def test_close_blends_to_neutral_then_ramps_weight_to_zero(run):
    arm = run["arm"]
    last_stream = max(
        i for i, a in enumerate(arm) if np.array_equal(a["q"], f32(run["expected"][-1]))
    )
    release = arm[last_stream + 1 :]
    assert len(release) == round(BLEND_S / 0.02) + round(RAMP_DOWN_S / 0.02)
    weights = np.array([a["weight"] for a in release])
    assert (
        np.all(np.diff(weights) <= 0)
        and weights[-1] == 0.0
        and np.all((weights >= 0) & (weights <= 1))
    )
    assert np.abs(np.diff(weights)).max() <= profiles.max_step(RAMP_DOWN_S, 0.02) + 1e-6
    assert np.allclose(release[-1]["q"], f32(NEUTRAL))


def test_measured_tracks_the_commands(run):
    # First-order lag of 0.05 s on a 1.2 s sine: within a few centiradians of the last targets.
    assert np.abs(run["measured"] - run["expected"][-2]).max() < 0.1


def test_close_twice_is_safe(run):
    assert run["second_close_sent"] == 0  # the arms were released once; nothing more went out
    assert run["backend"].state == "closed" and run["backend"].failure is None
    assert run["backend"].measured() is None


def test_recording_has_the_lowcmd_summary(run):
    rows = run["recording"]["/g1/lowcmd"]
    phases = [payload["phase"] for _, payload in rows]
    assert phases.count("stream") == N and phases.count("ramp_up") == round(RAMP_UP_S / 0.02)
    assert phases[-1] == "release"
    clamped = [payload["clamped"] for _, payload in rows if payload["phase"] == "stream"]
    assert clamped[-1] is True and not any(clamped[:-1])
