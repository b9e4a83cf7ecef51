"""The release plan and the torso's gravity, without DDS: the per-tick bound on what the feed-forwards
add (kd * dq* + tau), the weight ramp, tau 0 at weight 0; G under a tilted torso against MuJoCo's own
tilted model."""

from __future__ import annotations

import numpy as np
import pytest

from emopose.backends.g1.release import MAX_EFFORT_STEP_NM, MAX_STRETCH, Command, FeedLaw, plan_release
from emopose.backends.g1.torso import TorsoGravity
from emopose.robot import g1_spec
from emopose.robot.feedforward import MAX_VELOCITY_REFERENCE, GravityModel

DT = g1_spec.CONTROL_DT
KD = np.full(14, 1.5)
POSE = np.array([0.3, 0.25, 0.0, 0.9, 0.0, 0.1, 0.0, 0.3, -0.25, 0.0, 0.9, 0.0, 0.1, 0.0])


@pytest.fixture(scope="module")
def gravity() -> GravityModel:
    return GravityModel()


def moving(dq: float, gravity=None) -> Command:
    """The last stream command of an arm moving at dq rad/s on every joint."""
    tau = gravity(POSE) if gravity is not None else np.zeros(14)
    return Command(POSE, 1.0, np.full(14, dq), tau)


def test_without_feedforwards_it_blends_then_ramps_to_zero():
    neutral = np.zeros(14)
    plan = plan_release(moving(0.0), neutral, 0.5, 1.0, FeedLaw(KD, False, None, DT))
    assert len(plan) == 25 + 50
    assert np.all(plan.weight[:25] == 1.0) and plan.weight[-1] == 0.0 and np.all(np.diff(plan.weight) <= 0)
    assert np.array_equal(plan.q[24], neutral) and np.all(plan.q[25:] == neutral)
    assert not plan.dq.any() and not plan.tau.any()
    half = plan_release(Command(POSE, 0.5, np.zeros(14), np.zeros(14)), POSE, 0.5, 1.0,
                        FeedLaw(KD, False, None, DT))
    assert len(half) == 25 and half.weight[0] < 0.5  # a partial weight ramps down in less time, in place
    assert np.all(half.q == POSE)


@pytest.mark.parametrize("dq", [2.45, MAX_VELOCITY_REFERENCE])
@pytest.mark.parametrize("blend_s, ramp_s", [(2.0, 3.0), (0.2, 0.4), (0.0, 0.4)])
def test_a_release_mid_motion_fades_the_feedforwards_within_the_bound(gravity, dq, blend_s, ramp_s):
    law = FeedLaw(KD, True, gravity, DT)
    start = moving(dq, gravity)
    plan = plan_release(start, np.zeros(14), blend_s, ramp_s, law)
    # Before: dq* fell from dq to 0 in one tick, a kd * dq step of 3.7 N m (6 N m at the cap).
    assert plan.effort_step(start, KD) <= MAX_EFFORT_STEP_NM
    last = plan.commands()[-1]
    assert last.weight == 0.0 and not last.tau.any() and not last.dq.any()
    assert np.all(np.diff(plan.weight) <= 0)
    # Bounded time: the configured length under the defaults, stretched at most MAX_STRETCH times else.
    configured = round((blend_s + ramp_s) / DT)
    assert len(plan) == configured if blend_s == 2.0 else len(plan) <= MAX_STRETCH * max(configured, 38)


def test_a_short_ramp_under_a_steep_gravity_torque_is_stretched(gravity):
    start = Command(POSE, 1.0, np.zeros(14), gravity(POSE))
    law = FeedLaw(KD, False, gravity, DT)
    plan = plan_release(start, POSE, 0.0, 0.04, law)  # two ticks would drop several N m each
    assert plan.effort_step(start, KD) <= MAX_EFFORT_STEP_NM and len(plan) > 2


def tilted_model_gravity(q: np.ndarray, waist: np.ndarray, rpy: np.ndarray) -> np.ndarray:
    """G at the arms from MuJoCo's model with the pelvis and the waist turned by real hinges."""
    import mujoco

    from emopose.robot.model import build_spec

    spec = build_spec()
    hinge = mujoco.mjtJoint.mjJNT_HINGE
    for body, axes in (("pelvis", ((0, 1, 0), (1, 0, 0))), ("torso_link", ((0, 0, 1), (1, 0, 0), (0, 1, 0)))):
        for k, axis in enumerate(axes):
            spec.body(body).add_joint(name=f"{body}_{k}", type=hinge, axis=list(axis))
    model = spec.compile()
    data = mujoco.MjData(model)
    angles = {"pelvis_0": rpy[1], "pelvis_1": rpy[0], "torso_link_0": waist[0], "torso_link_1": waist[1],
              "torso_link_2": waist[2]}
    for name, value in [*angles.items(), *zip(g1_spec.JOINT_NAMES, q)]:
        data.qpos[model.joint(name).qposadr[0]] = value
    mujoco.mj_kinematics(model, data)
    mujoco.mj_comPos(model, data)
    out = np.zeros(model.nv)
    mujoco.mj_rne(model, data, 0, out)
    return out[[model.joint(n).dofadr[0] for n in g1_spec.JOINT_NAMES]]


@pytest.mark.parametrize("waist, rpy", [((0.0, 0.0, 0.52), (0.0, 0.0, 0.0)),
                                        ((0.3, -0.2, 0.4), (0.05, -0.1, 1.0)),
                                        ((0.0, 0.0, 0.0), (0.1, 0.2, 0.0))])
def test_gravity_feedforward_follows_the_measured_torso(gravity, waist, rpy):
    waist, rpy = np.array(waist), np.array(rpy)
    tilted = TorsoGravity(gravity, lambda: (waist, rpy))
    expected = tilted_model_gravity(POSE, waist, rpy)
    assert np.allclose(tilted(POSE), expected, atol=1e-9)
    upright = TorsoGravity(GravityModel(), lambda: None)(POSE)
    assert np.allclose(upright, tilted_model_gravity(POSE, np.zeros(3), np.zeros(3)), atol=1e-9)
    assert np.abs(expected - upright).max() > 0.3  # what an upright assumption gets wrong
