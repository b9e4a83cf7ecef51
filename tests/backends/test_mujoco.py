"""The MuJoCo backend and the project's G1 upper-body MJCF, checked against shared/reference/g1.md."""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")  # must precede the first mujoco import

import numpy as np
import pytest

from emopose.backends.base import Backend
from emopose.backends.mujoco import MujocoBackend
from emopose.recording import Recorder, read_recording
from emopose.robot.g1_spec import CONTROL_DT, JOINT_NAMES
from emopose.robot.model import build_model
from tests.backends.mujoco_run import NEUTRAL, run_ticks

# g1.md, left arm: body -> (pos, quat wxyz, range, torque limit, mass, COM).
LEFT_ARM = {
    "shoulder_pitch": (
        (0.0039563, 0.10022, 0.23778),
        (0.990264, 0.139201, 1.38722e-05, -9.86868e-05),
        (-3.0892, 2.6704),
        25,
        0.718,
        (0, 0.035892, -0.011628),
    ),
    "shoulder_roll": (
        (0, 0.038, -0.013831),
        (0.990268, -0.139172, 0, 0),
        (-1.5882, 2.2515),
        25,
        0.643,
        (-0.000227, 0.00727, -0.063243),
    ),
    "shoulder_yaw": (
        (0, 0.00624, -0.1032),
        (1, 0, 0, 0),
        (-2.618, 2.618),
        25,
        0.734,
        (0.010773, -0.002949, -0.072009),
    ),
    "elbow": (
        (0.015783, 0, -0.080518),
        (1, 0, 0, 0),
        (-1.0472, 2.0944),
        25,
        0.600,
        (0.064956, 0.004454, -0.010062),
    ),
    "wrist_roll": (
        (0.1, 0.00188791, -0.01),
        (1, 0, 0, 0),
        (-1.97222, 1.97222),
        25,
        0.085445,
        (0.0171394, 0.000537591, 0),
    ),
    "wrist_pitch": (
        (0.038, 0, 0),
        (1, 0, 0, 0),
        (-1.61443, 1.61443),
        5,
        0.48405,
        (0.0229999, -0.00111685, -0.00111658),
    ),
    "wrist_yaw": (
        (0.046, 0, 0),
        (1, 0, 0, 0),
        (-1.61443, 1.61443),
        5,
        0.254576,
        (0.0708244, 0.000191745, 0.00161742),
    ),
}
RIGHT_SHOULDER_PITCH_Y = -0.10021  # g1.md lists the right shoulder's y separately
HELD_POSE = np.array([-0.5, 0.2, 0, 1.0, 0, 0, 0, -0.5, -0.2, 0, 1.0, 0, 0, 0])
SINE_CENTER = np.array([-0.4, 0.45, 0, 0.9, 0, 0, 0, -0.4, -0.45, 0, 0.9, 0, 0, 0])
# Left shoulder pitched forward, upper arm yawed inward, forearm raised: the hand meets the chest.
HAND_ON_CHEST = np.concatenate([[-0.6, 0.0, -1.2, -0.5, 0, 0, 0], NEUTRAL[7:]])


def _expected(side: str, link: str):
    pos, quat, rng, limit, mass, com = LEFT_ARM[link]
    if side == "right":  # mirror y, negate quaternion x and z, mirror the roll range
        pos = (pos[0], RIGHT_SHOULDER_PITCH_Y if link == "shoulder_pitch" else -pos[1], pos[2])
        quat = (quat[0], -quat[1], quat[2], -quat[3])
        com = (com[0], -com[1], com[2])
        rng = (-rng[1], -rng[0]) if link == "shoulder_roll" else rng
    return pos, quat, rng, limit, mass, com


@pytest.fixture
def backend():
    b = MujocoBackend()
    yield b
    b.close()


def test_model_matches_g1_reference():
    m = build_model()
    assert m.opt.timestep <= 0.002
    assert [m.actuator(i).name for i in range(m.nu)] == list(JOINT_NAMES)
    for name in JOINT_NAMES:
        side, link = name.split("_", 1)
        link = link.removesuffix("_joint")
        pos, quat, rng, limit, mass, com = _expected(side, link)
        body, joint, act = m.body(f"{side}_{link}_link"), m.joint(name), m.actuator(name)
        np.testing.assert_allclose(body.pos, pos, atol=1e-9, err_msg=name)
        np.testing.assert_allclose(
            body.quat, np.array(quat) / np.linalg.norm(quat), atol=1e-6, err_msg=name
        )
        np.testing.assert_allclose(joint.range, rng, err_msg=name)
        np.testing.assert_allclose(act.ctrlrange, rng, err_msg=name)
        np.testing.assert_allclose(act.forcerange, (-limit, limit), err_msg=name)
        np.testing.assert_allclose(m.jnt_actfrcrange[joint.id], (-limit, limit), err_msg=name)
        assert body.mass[0] == pytest.approx(mass), name
        np.testing.assert_allclose(body.ipos, com, atol=1e-9, err_msg=name)
        assert 0.05 <= joint.damping[0] <= 0.1 and joint.armature[0] == pytest.approx(0.01)
    assert m.body("torso_link").mass[0] == pytest.approx(9.598)


def test_backend_protocol_and_zero_pose_geometry():
    backend = MujocoBackend(initial_pose=[0.0] * 14)
    assert isinstance(backend, Backend) and backend.name == "mujoco"
    assert backend.measured() is None
    np.testing.assert_allclose(backend.connect(None), np.zeros(14))
    d = backend.data
    for side in ("left", "right"):
        shoulder, elbow = (
            d.body(f"{side}_shoulder_roll_link").xpos,
            d.body(f"{side}_elbow_link").xpos,
        )
        wrist = d.body(f"{side}_wrist_yaw_link").xpos
        assert shoulder[2] - elbow[2] > 0.15  # upper arm hangs down at zero
        assert (
            wrist[0] - elbow[0] > 0.15 and abs(wrist[2] - elbow[2]) < 0.03
        )  # forearm points forward
    assert 0.40 <= d.geom("head").xpos[2] - d.body("pelvis").xpos[2] <= 0.45
    assert backend.contacts() == []


def test_send_returns_the_target_clipped_to_the_joint_ranges(backend):
    assert not backend.is_connected
    backend.connect(None)
    assert backend.is_connected
    lo, hi = backend.model.jnt_range[[backend.model.joint(n).id for n in JOINT_NAMES]].T
    asked = np.where(np.arange(14) % 2 == 0, hi + 0.5, lo - 0.5)  # every joint past a limit
    sent = backend.send(0.0, asked)
    np.testing.assert_allclose(sent, np.clip(asked, lo, hi))
    inside = (lo + hi) / 2
    np.testing.assert_allclose(backend.send(CONTROL_DT, inside), inside)
    backend.close()
    assert not backend.is_connected


def test_holds_pose_with_gravity_compensation_within_torque_limits(backend):
    backend.connect(None)
    measured = run_ticks(backend, np.tile(HELD_POSE, (100, 1)))  # 2 s
    assert np.max(np.abs(measured[-1] - HELD_POSE)) < 0.01
    assert backend.max_actuator_force_ratio <= 1.0 + 1e-9
    m, d = backend.model, backend.data
    assert np.all(np.abs(d.actuator_force) <= m.actuator_forcerange[:, 1] + 1e-9)
    # Holding costs only gravity torque: well inside every limit.
    assert np.max(np.abs(backend.joint_torques()) / m.jnt_actfrcrange[:, 1]) < 0.5


def test_tracks_sinusoid_at_50hz():
    backend = MujocoBackend(initial_pose=SINE_CENTER.tolist())
    backend.connect(None)
    t = np.arange(0, 4, CONTROL_DT)
    phase = np.linspace(0, 2 * np.pi, 14, endpoint=False)
    targets = SINE_CENTER + 0.3 * np.sin(2 * np.pi * 0.5 * t[:, None] + phase)
    measured = run_ticks(backend, targets)
    after = t >= 0.5
    mae = np.mean(np.abs(measured[after] - targets[after]))
    backend.close()
    assert mae < 0.01, mae
    assert backend.max_actuator_force_ratio <= 1.0 + 1e-9


def test_hand_pushed_into_torso_is_a_self_contact(backend):
    backend.connect(None)
    ramp = np.linspace(NEUTRAL, HAND_ON_CHEST, 50)
    run_ticks(backend, np.vstack([ramp, np.tile(HAND_ON_CHEST, (25, 1))]))
    contacts = backend.contacts()
    assert any("left_hand" in pair and {"chest", "abdomen"} & set(pair) for pair in contacts), (
        contacts
    )
    assert all("floor" not in pair for pair in contacts)


def test_records_sim_and_torque_streams(tmp_path, backend):
    with Recorder(tmp_path / "run.mcap") as recorder:
        backend.connect(recorder)
        run_ticks(backend, np.tile(HELD_POSE, (5, 1)))
    streams = read_recording(tmp_path / "run.mcap")
    assert len(streams["/joints/sim"]) == len(streams["/joints/torque"]) == 5
    assert "/joints/command" not in streams  # the control loop records the commanded stream, once
    assert streams["/joints/sim"][0][1]["t"] == pytest.approx(CONTROL_DT)  # state at end of period
    assert len(streams["/joints/torque"][0][1]["tau"]) == 14
