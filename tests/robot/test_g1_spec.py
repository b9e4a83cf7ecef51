"""emopose.robot.g1_spec is the one source of the G1's arm facts; the data files that keep their own
copies (library/g1/limits.yaml, the MJCF) must agree with it, and the Python code must import it."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import yaml

import emopose
from emopose.backends.g1.settings import G1Settings
from emopose.robot import g1_spec
from emopose.robot.model import build_model

REPO = Path(__file__).resolve().parents[2]


def test_spec_figures():
    assert g1_spec.NUM_JOINTS == len(g1_spec.JOINT_NAMES) == 14 and g1_spec.ARM_DOF == 7
    assert g1_spec.JOINT_NAMES[0] == "left_shoulder_pitch_joint"
    assert g1_spec.JOINT_NAMES[8] == "right_shoulder_roll_joint"
    assert tuple(range(15, 29)) == g1_spec.ARM_MOTORS and g1_spec.WEIGHT_MOTOR == 29
    assert g1_spec.CONTROL_DT == 0.02 and g1_spec.CONTROL_HZ * g1_spec.CONTROL_DT == 1.0
    lower, upper = np.array(g1_spec.LOWER), np.array(g1_spec.UPPER)
    assert np.all(lower < upper)
    # The arms mirror each other except shoulder roll, whose range is mirrored (g1.md).
    roll = g1_spec.ARM_JOINTS.index("shoulder_roll")
    assert (lower[7 + roll], upper[7 + roll]) == (-upper[roll], -lower[roll])
    same = [j for j in range(7) if j != roll]
    np.testing.assert_array_equal(lower[same], lower[[7 + j for j in same]])


def test_package_constants_are_the_specs():
    assert (emopose.CONTROL_DT, emopose.NUM_JOINTS) == (g1_spec.CONTROL_DT, g1_spec.NUM_JOINTS)


def test_limits_yaml_agrees_with_the_spec():
    data = yaml.safe_load((REPO / "library" / "g1" / "limits.yaml").read_text())
    assert tuple(data["joints"]) == g1_spec.JOINT_NAMES
    assert tuple(data["lower"]) == g1_spec.LOWER and tuple(data["upper"]) == g1_spec.UPPER


def test_mjcf_ranges_agree_with_the_spec():
    model = build_model()
    ranges = np.array([model.joint(n).range for n in g1_spec.JOINT_NAMES])
    np.testing.assert_allclose(ranges, np.column_stack([g1_spec.LOWER, g1_spec.UPPER]), atol=1e-9)
    ctrl = np.array([model.actuator(n).ctrlrange for n in g1_spec.JOINT_NAMES])
    np.testing.assert_allclose(ctrl, ranges, atol=1e-9)


def test_g1_backend_defaults_to_the_spec_limits():
    kw = dict(domain_id=0, network_interface=None, lowstate_timeout_s=1, lowstate_loss_ms=200,
              deadman_ms=100, kp=60, kd=1.5, weight_ramp_up_s=1, weight_ramp_down_s=1,
              release_blend_s=0, neutral_pose=None, lower=None, upper=None, command_waist=False,
              waist_kp=0, waist_kd=0)
    s = G1Settings.build(**kw)
    assert tuple(s.lower) == g1_spec.LOWER and tuple(s.upper) == g1_spec.UPPER


FACTS = {"JOINT_NAMES", "NUM_JOINTS", "CONTROL_DT", "CONTROL_HZ", "ARM_DOF", "NUM_MOTORS",
         "ARM_MOTORS", "WAIST_MOTORS", "WEIGHT_MOTOR"}


def test_no_other_module_defines_a_spec_fact():
    """Assignments only: importing (and re-exporting) the spec's names is how they are shared."""
    owners: dict[str, set[str]] = {}
    for path in sorted((REPO / "emopose").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            targets = node.targets if isinstance(node, ast.Assign) else [getattr(node, "target", None)]
            for target in targets:
                if isinstance(target, ast.Name) and target.id in FACTS:
                    owners.setdefault(target.id, set()).add(path.relative_to(REPO).as_posix())
    assert set(owners) == FACTS and all(f == {"emopose/robot/g1_spec.py"} for f in owners.values()), owners
