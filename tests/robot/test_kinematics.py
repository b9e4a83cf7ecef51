"""Arm FK vs. the g1.md figures, MuJoCo, mirror symmetry and finite differences."""

from __future__ import annotations

import numpy as np
import pytest

from emopose.robot import kinematics as K

REST = np.array([0.1, 0.12, 0.0, 1.2, 0.0, 0.0, 0.0, 0.1, -0.12, 0.0, 1.2, 0.0, 0.0, 0.0])


def test_zero_pose_matches_g1_geometry():
    rot, pos = K.link_frames(np.zeros(14))
    np.testing.assert_allclose(pos[0, 0], [0.0039563, 0.10022, 0.23778], atol=1e-9)  # shoulder pitch body
    np.testing.assert_allclose(pos[1, 0], [0.0039563, -0.10021, 0.23778], atol=1e-9)
    shoulder, elbow, wrist, tip = K.arm_points(np.zeros(14))[0]
    assert 0.17 < shoulder[2] - elbow[2] < 0.20  # upper arm hangs straight down ...
    assert abs(elbow[0] - shoulder[0]) < 0.03 and abs(elbow[1] - shoulder[1]) < 0.01
    assert wrist[0] - elbow[0] == pytest.approx(0.184, abs=0.002)  # ... and the forearm points forward
    assert abs(wrist[2] - elbow[2]) < 0.015
    assert tip[0] - shoulder[0] > 0.3  # the hand is well forward of the shoulder
    assert 0.13 < shoulder[1] < 0.15 and 0.2 < shoulder[2] < 0.25
    # The shoulder quaternions nearly cancel: at q = 0 the hand frame is aligned with the torso.
    np.testing.assert_allclose(rot[..., 6, :, :], np.broadcast_to(np.eye(3), (2, 3, 3)), atol=1e-3)


def test_rotations_are_orthonormal_and_shapes_broadcast():
    q = np.random.default_rng(0).uniform(-1.5, 1.5, (4, 5, 14))
    rot, pos = K.link_frames(q)
    assert rot.shape == (4, 5, 2, 7, 3, 3) and pos.shape == (4, 5, 2, 7, 3)
    np.testing.assert_allclose(
        rot @ np.swapaxes(rot, -1, -2), np.broadcast_to(np.eye(3), rot.shape), atol=1e-12
    )
    np.testing.assert_allclose(np.linalg.det(rot), 1.0, atol=1e-12)
    assert K.arm_points(q).shape == (4, 5, 2, 4, 3)
    assert K.arm_points(q[0, 0]).shape == (2, 4, 3)
    np.testing.assert_allclose(K.arm_points(q)[1, 2], K.arm_points(q[1, 2]))
    with pytest.raises(ValueError):
        K.arm_points(np.zeros(7))


def test_left_right_mirror_symmetry():
    q = np.random.default_rng(1).uniform(-1.5, 1.5, (20, 14))
    points, mirrored = K.arm_points(q), K.arm_points(K.mirror(q))
    reflect = np.array([1.0, -1.0, 1.0])
    # g1.md puts the right shoulder 10 microns closer to the midline than an exact mirror.
    np.testing.assert_allclose(mirrored[:, ::-1] * reflect, points, atol=2e-5)
    np.testing.assert_allclose(K.mirror(K.mirror(q)), q)
    point, palm = K.hand_axes(q)
    point_m, palm_m = K.hand_axes(K.mirror(q))
    np.testing.assert_allclose(point_m[:, ::-1] * reflect, point, atol=1e-12)
    np.testing.assert_allclose(palm_m[:, ::-1] * reflect, palm, atol=1e-12)


def _delta(joint: int, value: float, left: bool = True) -> np.ndarray:
    """REST with one joint of one arm moved to `value` (the right arm gets the mirrored value)."""
    q = REST.copy()
    q[joint if left else joint + 7] = value if left else value * K.MIRROR_SIGNS[joint]
    return q


@pytest.mark.parametrize("left", [True, False])
def test_sign_conventions(left):
    side, out = (0, 1.0) if left else (1, -1.0)  # `out` is the sign of y pointing away from the body
    rest = K.arm_points(REST)[side]
    raised = K.arm_points(_delta(0, -1.5, left))[side]  # shoulder_pitch < 0: arm forward and up
    assert raised[1, 0] > rest[1, 0] + 0.15 and raised[1, 2] > rest[1, 2] + 0.1
    abducted = K.arm_points(_delta(1, 1.2, left))[side]  # roll: +left / -right moves the arm outward
    assert (abducted[1, 1] - rest[1, 1]) * out > 0.1
    q = _delta(3, 0.0, left)  # forearm forward, then yaw: +left / -right turns it outward
    turned = K.arm_points(q + _delta(2, 0.8, left) - REST)[side]
    assert (turned[3, 1] - K.arm_points(q)[side][3, 1]) * out > 0.1
    straight = np.zeros(14)
    straight[[3, 10]] = np.pi / 2  # elbow +pi/2 from the all-zero pose: the arm hangs straight down
    straight = K.arm_points(straight)[side]
    assert straight[3, 2] < straight[1, 2] - 0.25 and abs(straight[3, 0] - straight[1, 0]) < 0.03
    _, palm = K.hand_axes(REST)
    assert palm[side, 1] * out < -0.9  # palms face the body midline at rest
    forward = np.zeros(14)  # forearms forward; wrist roll +left / -right turns the palm down
    forward[[4, 11]] = 1.5, -1.5
    _, palm = K.hand_axes(forward)
    assert palm[side, 2] < -0.95


@pytest.mark.parametrize("side", [0, 1])
def test_hand_jacobian_matches_finite_differences(side):
    q = np.random.default_rng(2 + side).uniform(-1.0, 1.0, (6, 14))
    jac = K.hand_jacobian(q, side)
    assert jac.shape == (6, 3, 7)
    h = 1e-6
    for j in range(7):
        step = np.zeros(14)
        step[7 * side + j] = h
        numeric = (K.arm_points(q + step)[:, side, 3] - K.arm_points(q - step)[:, side, 3]) / (2 * h)
        np.testing.assert_allclose(jac[:, :, j], numeric, atol=1e-7)
    assert K.hand_jacobian(q[0], side).shape == (3, 7)


# The g1.md chain table, written out independently of the module's constants.
_G1_TABLE = {
    "left": [
        ("0.0039563 0.10022 0.23778", "0.990264 0.139201 1.38722e-05 -9.86868e-05", "0 1 0"),
        ("0 0.038 -0.013831", "0.990268 -0.139172 0 0", "1 0 0"),
        ("0 0.00624 -0.1032", "1 0 0 0", "0 0 1"),
        ("0.015783 0 -0.080518", "1 0 0 0", "0 1 0"),
        ("0.1 0.00188791 -0.01", "1 0 0 0", "1 0 0"),
        ("0.038 0 0", "1 0 0 0", "0 1 0"),
        ("0.046 0 0", "1 0 0 0", "0 0 1"),
    ],
    "right": [
        ("0.0039563 -0.10021 0.23778", "0.990264 -0.139201 1.38722e-05 9.86868e-05", "0 1 0"),
        ("0 -0.038 -0.013831", "0.990268 0.139172 0 0", "1 0 0"),
        ("0 -0.00624 -0.1032", "1 0 0 0", "0 0 1"),
        ("0.015783 0 -0.080518", "1 0 0 0", "0 1 0"),
        ("0.1 -0.00188791 -0.01", "1 0 0 0", "1 0 0"),
        ("0.038 0 0", "1 0 0 0", "0 1 0"),
        ("0.046 0 0", "1 0 0 0", "0 0 1"),
    ],
}


def test_matches_mujoco_built_from_the_g1_table():
    mujoco = pytest.importorskip("mujoco")
    bodies = ""
    for side, chain in _G1_TABLE.items():
        xml, close = "", ""
        for j, (pos, quat, axis) in enumerate(chain):
            xml += f'<body name="{side}{j}" pos="{pos}" quat="{quat}">'
            xml += f'<joint axis="{axis}"/><geom size="0.01"/>'
            close += "</body>"
        bodies += xml + f'<site name="{side}_tip" pos="{K.HAND_TIP} 0 0"/>' + close
    model = mujoco.MjModel.from_xml_string(f"<mujoco><worldbody>{bodies}</worldbody></mujoco>")
    data = mujoco.MjData(model)
    for q in np.random.default_rng(4).uniform(-2.0, 2.0, (10, 14)):
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        rot, pos = K.link_frames(q)
        for s, side in enumerate(_G1_TABLE):
            for j in range(7):
                body = model.body(f"{side}{j}").id
                np.testing.assert_allclose(pos[s, j], data.xpos[body], atol=1e-9)
                np.testing.assert_allclose(rot[s, j], data.xmat[body].reshape(3, 3), atol=1e-9)
            np.testing.assert_allclose(K.arm_points(q)[s, 3], data.site(f"{side}_tip").xpos, atol=1e-9)
