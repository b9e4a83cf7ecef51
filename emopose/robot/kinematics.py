"""Pure-numpy forward kinematics of the G1's two 7-DoF arms, in the `torso_link` frame.

Figures are the left-arm chain of g1.md (Unitree's 29-DoF MJCF); the right arm mirrors every y
value and the quaternions' x and z parts. Everything is vectorised over leading sample axes: a
(T, 14) joint array gives (T, 2, ...) results, side 0 = left, side 1 = right.

Sign conventions (tests/robot/test_kinematics.py checks them); at q = 0 the upper arms hang down
and the forearms point forward:
  shoulder_pitch  - raises the arm forward and up (about -2.9 is overhead), + swings it back; the
                  axis is tilted 16 deg, so raising also brings the arm in towards the midline
  shoulder_roll   moves the arm outward (abduction) for + on the left, - on the right
  shoulder_yaw    turns the forearm outward for + on the left, - on the right
  elbow           0 = 90 deg bend; + extends (about +1.57 is straight), - flexes the hand up
  wrist_roll      + on the left / - on the right turns the palm down (palms face inward at 0)
  wrist_pitch     + tips the fingers down (in the palm's plane); wrist_yaw + on the left /
                  - on the right bends the hand back, away from the palm
So a left-arm pose becomes the mirrored right-arm pose with MIRROR_SIGNS.
"""

from __future__ import annotations

import numpy as np

from emopose.robot.g1_spec import ARM_DOF, ARM_JOINTS

LEFT, RIGHT = 0, 1
MIRROR_SIGNS = np.array([1.0, -1.0, -1.0, 1.0, -1.0, 1.0, -1.0])  # q_right = MIRROR_SIGNS * q_left

# Left chain from g1.md: body position in its parent, body quaternion (w x y z), joint axis
# (0 = x, 1 = y, 2 = z), from shoulder_pitch_link to wrist_yaw_link.
_LEFT_POS = np.array([
    [0.0039563, 0.10022, 0.23778],
    [0.0, 0.038, -0.013831],
    [0.0, 0.00624, -0.1032],
    [0.015783, 0.0, -0.080518],
    [0.1, 0.00188791, -0.01],
    [0.038, 0.0, 0.0],
    [0.046, 0.0, 0.0],
])  # fmt: skip
_LEFT_QUAT = np.array(
    [[0.990264, 0.139201, 1.38722e-05, -9.86868e-05], [0.990268, -0.139172, 0.0, 0.0]]
    + [[1.0, 0.0, 0.0, 0.0]] * 5
)
_RIGHT_SHOULDER_PITCH_Y = -0.10021  # g1.md's value, 10 microns off an exact mirror of 0.10022
AXES = (1, 0, 2, 1, 0, 1, 2)

# The rubber hand (g1.md): its body sits 0.0415 m along +x of wrist_yaw_link and a capsule of radius
# 0.035 m over the next 0.10 m stands in for it (as in emopose/robot/assets/g1_upper_body.xml).
HAND_ORIGIN, HAND_END, HAND_RADIUS = 0.0415, 0.1415, 0.035
HAND_TIP = HAND_END + HAND_RADIUS  # fingertips: the far end of that capsule
PALM_NORMAL_LEFT = np.array([0.0, -1.0, 0.0])  # in wrist_yaw_link: palms face the midline at q = 0


def _quat_to_matrix(q: np.ndarray) -> np.ndarray:
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])  # fmt: skip


def _chain_constants() -> tuple[np.ndarray, np.ndarray]:
    """First body rotation (as its 3 columns) and per-joint angle offsets of the left chain.

    Every body quaternion after the first is a pure rotation about its own joint's axis (asserted),
    so it folds into that joint's angle and the chain only ever rotates about coordinate axes.
    """
    offsets = np.zeros(ARM_DOF)
    for j in range(1, ARM_DOF):
        w, vec = _LEFT_QUAT[j, 0], _LEFT_QUAT[j, 1:]
        assert np.allclose(np.delete(vec, AXES[j]), 0.0), "body must rotate about its joint axis"
        offsets[j] = 2.0 * np.arctan2(vec[AXES[j]], w)
    return _quat_to_matrix(_LEFT_QUAT[0]).T, offsets


_ROT0_COLS, _OFFSETS = _chain_constants()
_P0_NONZERO = tuple(tuple(int(k) for k in np.flatnonzero(p)) for p in _LEFT_POS)
# Rotating about axis a mixes the other two columns (u, v): u' = c u + s v, v' = c v - s u.
_MIX = tuple(((a + 1) % 3, (a + 2) % 3) for a in AXES)
# The right arm is the mirror image (y -> -y) of the left chain driven by MIRROR_SIGNS * q; only
# its root sits 10 microns off the mirror, and that constant shift is added back exactly.
_SIDE_SIGNS = np.stack([np.ones(ARM_DOF), MIRROR_SIGNS])
_RIGHT_ROOT_SHIFT = _RIGHT_SHOULDER_PITCH_Y + _LEFT_POS[0, 1]


def _as_arms(q: np.ndarray) -> tuple[np.ndarray, tuple[int, ...]]:
    q = np.asarray(q, dtype=float)
    if q.shape[-1] != 2 * ARM_DOF:
        raise ValueError(f"expected (..., {2 * ARM_DOF}) joint angles, got shape {q.shape}")
    return q.reshape(-1, 2, ARM_DOF), q.shape[:-1]


def mirrored_chain(qa: np.ndarray, dtype: type = np.float64) -> tuple[list, list]:
    """Core FK on (N, 2, 7) angles: both arms run through the left chain, the right one mirrored.

    Returns per link j the rotation's three columns cols[j][k] and the origin pos[j], each a (3, 2N)
    component plane, side-major along the last axis, right half still mirrored (see `unmirror`).
    Every numpy call works on a whole (3, 2N) block and an unchanged column is shared, not copied:
    the call count is what makes the collision check fast. float32 halves the cost again (its
    sin/cos are much cheaper) at sub-micron error.
    """
    n = qa.shape[0]
    theta = (qa * _SIDE_SIGNS).transpose(2, 1, 0).reshape(ARM_DOF, 2 * n).astype(dtype)
    theta += _OFFSETS[:, None].astype(dtype)
    c, s = np.cos(theta), np.sin(theta)
    cols = [np.broadcast_to(col.astype(dtype)[:, None], (3, 2 * n)) for col in _ROT0_COLS]
    pos = np.broadcast_to(_LEFT_POS[0].astype(dtype)[:, None], (3, 2 * n))
    all_cols, all_pos = [], []
    for j in range(ARM_DOF):
        for k in _P0_NONZERO[j] if j else ():
            pos = pos + cols[k] * dtype(_LEFT_POS[j, k])
        u, v = _MIX[j]
        cols = list(cols)
        cols[u], cols[v] = c[j] * cols[u] + s[j] * cols[v], c[j] * cols[v] - s[j] * cols[u]
        all_cols.append(cols)
        all_pos.append(pos)
    return all_cols, all_pos


def unmirror(planes: np.ndarray, points: bool) -> np.ndarray:
    """Map the right half of (3, 2, ...) mirrored-chain planes onto the right arm, in place."""
    planes[1, 1] *= -1.0
    if points:
        planes[1, 1] += _RIGHT_ROOT_SHIFT
    return planes


def link_frames(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotations (..., 2, 7, 3, 3) and origins (..., 2, 7, 3) of both arms' 7 links, torso frame.

    Link j is the child body of joint j, so its origin lies on joint j's axis.
    """
    qa, lead = _as_arms(q)
    n = qa.shape[0]
    cols, pos = mirrored_chain(qa)
    rot = np.array(cols).reshape(ARM_DOF, 3, 3, 2, n)  # (link, col, comp, side, N)
    rot[:, :, 1, 1] *= -1.0  # right arm: R -> S R S with S = diag(1, -1, 1)
    rot[:, 1, :, 1] *= -1.0
    pos = unmirror(np.array(pos).reshape(ARM_DOF, 3, 2, n).transpose(1, 2, 0, 3), points=True)
    rot = rot.transpose(4, 3, 0, 2, 1)  # (N, side, link, comp, col): ordinary rotation matrices
    pos = pos.transpose(3, 1, 2, 0)
    return rot.reshape(*lead, 2, ARM_DOF, 3, 3), pos.reshape(*lead, 2, ARM_DOF, 3)


def hand_point(rot: np.ndarray, pos: np.ndarray, along_x: float) -> np.ndarray:
    """The point `along_x` metres along the wrist_yaw link's +x axis (the hand's pointing axis)."""
    return pos[..., -1, :] + along_x * rot[..., -1, :, 0]


def arm_points(q: np.ndarray) -> np.ndarray:
    """(..., 2, 4, 3): shoulder (roll link origin), elbow, wrist (wrist_yaw origin), hand tip."""
    rot, pos = link_frames(q)
    tip = hand_point(rot, pos, HAND_TIP)
    return np.stack([pos[..., 1, :], pos[..., 3, :], pos[..., 6, :], tip], axis=-2)


def hand_axes(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit pointing direction (hand +x) and palm normal of each hand, each (..., 2, 3)."""
    rot, _ = link_frames(q)
    hand = rot[..., -1, :, :]
    palm_local = np.stack([PALM_NORMAL_LEFT, PALM_NORMAL_LEFT * np.array([1.0, -1.0, 1.0])])
    return hand[..., :, 0], np.einsum("...sab,sb->...sa", hand, palm_local)


def hand_jacobian(q: np.ndarray, side: int, along_x: float = HAND_TIP) -> np.ndarray:
    """Geometric Jacobian (..., 3, 7) of one hand point w.r.t. its arm's 7 joints, library order."""
    rot, pos = link_frames(q)
    rot, pos = rot[..., side, :, :, :], pos[..., side, :, :]
    point = hand_point(rot, pos, along_x)
    axes = np.stack([rot[..., j, :, a] for j, a in enumerate(AXES)], axis=-2)  # world joint axes
    return np.swapaxes(np.cross(axes, point[..., None, :] - pos), -1, -2)


def arms_apart(q: np.ndarray, angle: float) -> np.ndarray:
    """q with both shoulders rolled `angle` rad further outward: the hands part sideways, so a path
    between two hands-together poses (clasped, on the heart) need not pass them through each other."""
    out = np.array(q, dtype=float)
    roll = ARM_JOINTS.index("shoulder_roll")
    out[..., roll] += angle
    out[..., ARM_DOF + roll] += MIRROR_SIGNS[roll] * angle
    return out


def mirror(q: np.ndarray) -> np.ndarray:
    """Swap the arms of a (..., 14) configuration, mirroring it through the sagittal plane."""
    q = np.asarray(q, dtype=float)
    left, right = q[..., :ARM_DOF], q[..., ARM_DOF:]
    return np.concatenate([right * MIRROR_SIGNS, left * MIRROR_SIGNS], axis=-1)
