"""The facts of the Unitree G1 (29-DoF) arms that this project relies on, stated once.

Every Python module takes joint names, joint limits, motor indices and the control period from
here. Two data files keep their own copies because they are read by other tools: the joint
limits in library/g1/limits.yaml and the joint ranges in assets/g1_upper_body.xml; tests/robot/
test_g1_spec.py checks that both agree with this module. Figures: shared/reference/g1.md.
Plain tuples, no imports: importable from anywhere (config tests, the G1 backend without
cyclonedds, emopose/__init__.py).
"""

from __future__ import annotations

SIDES = ("left", "right")
ARM_JOINTS = (
    "shoulder_pitch",
    "shoulder_roll",
    "shoulder_yaw",
    "elbow",
    "wrist_roll",
    "wrist_pitch",
    "wrist_yaw",
)
ARM_DOF = len(ARM_JOINTS)
# The motion library's joint order: left arm 0-6, then the right arm 7-13.
JOINT_NAMES: tuple[str, ...] = tuple(f"{side}_{j}_joint" for side in SIDES for j in ARM_JOINTS)
NUM_JOINTS = len(JOINT_NAMES)

# The arm_sdk stream rate used by Unitree's own arm example and by our sequencer.
CONTROL_HZ = 50.0
CONTROL_DT = 1.0 / CONTROL_HZ

# LowCmd_/LowState_ motor slots: 0-11 legs, 12-14 waist, 15-28 arms in JOINT_NAMES order, and
# motor_cmd[29].q in [0, 1], how much the firmware blends in the arm_sdk targets.
NUM_MOTORS = 35
WAIST_MOTORS = (12, 13, 14)  # waist yaw, roll, pitch
ARM_MOTORS = tuple(range(15, 15 + NUM_JOINTS))
WEIGHT_MOTOR = 29

# Hardware joint ranges (rad) of the left arm, in ARM_JOINTS order (g1.md's "range" column).
_LEFT_RANGES = (
    (-3.0892, 2.6704),
    (-1.5882, 2.2515),
    (-2.618, 2.618),
    (-1.0472, 2.0944),
    (-1.97222, 1.97222),
    (-1.61443, 1.61443),
    (-1.61443, 1.61443),
)
# The right arm has the same ranges except shoulder roll, which is mirrored.
_RIGHT_RANGES = tuple(
    (-hi, -lo) if joint == "shoulder_roll" else (lo, hi)
    for joint, (lo, hi) in zip(ARM_JOINTS, _LEFT_RANGES)
)
LOWER: tuple[float, ...] = tuple(lo for lo, _ in _LEFT_RANGES + _RIGHT_RANGES)
UPPER: tuple[float, ...] = tuple(hi for _, hi in _LEFT_RANGES + _RIGHT_RANGES)
