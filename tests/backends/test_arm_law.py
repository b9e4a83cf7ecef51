"""One arm law for the G1 command and the simulator: gains, gravity and velocity feed-forwards."""

from __future__ import annotations

import numpy as np
import pytest
from hydra.utils import instantiate

from emopose import CONTROL_DT
from emopose.backends.g1.arm_command import ArmCommandBuilder, decode_arm_command
from emopose.backends.g1.wire import lowcmd_from_cdr
from emopose.backends.mujoco import MujocoBackend
from emopose.execution.trajectory import smoothstep
from emopose.robot.arm_law import ArmLaw
from emopose.robot.feedforward import MAX_VELOCITY_REFERENCE, Feedforward, GravityModel
from emopose.sync.strokes import first_within

ROBOT_PLAIN = ArmLaw("robot_plain", 60.0, 1.5)
ROBOT_GRAVITY = ArmLaw("robot_gravity", 60.0, 1.5, gravity_compensation=True)
MJCF = ArmLaw("mjcf", None, None, velocity_feedforward=True, gravity_compensation=True)
# Right arm forward.
RAISED = np.array([0.1, 0.12, 0.0, 1.2, 0.0, 0.0, 0.0, -1.4, -0.3, 0.0, 1.5, 0.0, 0.0, 0.0])


@pytest.fixture(scope="module")
def gravity() -> GravityModel:
    return GravityModel()


def test_the_plain_law_sends_no_feedforward_and_the_gravity_law_sends_the_model_torque(gravity):
    plain, fed = Feedforward(ROBOT_PLAIN), Feedforward(ROBOT_GRAVITY, gravity)
    for ff in (plain, fed):
        ff.reset(np.zeros(14))
    dq, tau = plain(RAISED)
    assert not dq.any() and not tau.any()
    dq, tau = fed(RAISED)
    assert not dq.any() and np.allclose(tau, gravity(RAISED))
    assert abs(tau[7]) > 2.0  # holding a raised arm takes a few N m at the shoulder


def test_the_velocity_reference_is_the_capped_finite_difference():
    ff = Feedforward(ArmLaw("v", 60.0, 1.5, velocity_feedforward=True))
    ff.reset(np.zeros(14))
    step = np.zeros(14)
    step[0], step[1] = 0.02, 1.0  # 1 rad/s, then a 50 rad/s jump
    dq, _ = ff(step)
    assert dq[0] == pytest.approx(0.02 / CONTROL_DT) and dq[1] == MAX_VELOCITY_REFERENCE


def test_the_g1_command_carries_the_feedforwards(gravity):
    builder = ArmCommandBuilder(np.full(14, 60.0), np.full(14, 1.5))
    tau = gravity(RAISED)
    cdr, _ = builder.build(RAISED, 1.0, np.full(14, 0.5), tau)
    sent = decode_arm_command(lowcmd_from_cdr(cdr))
    assert np.allclose(sent["tau"], tau, atol=1e-5) and np.allclose(sent["dq"], 0.5)
    assert sent["crc_ok"] and sent["kp"] == [60.0] * 14
    cdr, _ = builder.build(RAISED, 1.0)  # no feed-forwards (robot_plain): pure position targets
    sent = decode_arm_command(lowcmd_from_cdr(cdr))
    assert not any(sent["tau"]) and not any(sent["dq"])


def sag_after_holding(law: ArmLaw) -> float:
    backend = MujocoBackend(law=law, initial_pose=RAISED.tolist())
    backend.connect(None)
    for n in range(100):  # 2 s holding the raised arm
        backend.send(n * CONTROL_DT, RAISED)
    sag = float(np.max(np.abs(backend.measured() - RAISED)))
    backend.close()
    return sag


def test_mujoco_applies_the_law_the_robot_is_sent():
    plain, fed, own = (sag_after_holding(law) for law in (ROBOT_PLAIN, ROBOT_GRAVITY, MJCF))
    assert plain > 0.03  # kp 60 and no gravity torque: the arm hangs below its target, as the G1's would
    assert fed < 0.005 and own < 0.005


def arrival_delay_ticks(law: ArmLaw) -> int:
    """Ticks between the command and the simulated arm coming within the stroke tolerance of a raised
    pose, after a preparation from rest about as fast as the planning speed bound allows (1.5 rad in 0.46 s:
    a first gesture squeezed into the speech pre-roll)."""
    backend = MujocoBackend(law=law, initial_pose=[0.0] * len(RAISED))  # the arms hanging straight down
    backend.connect(None)
    rest = backend.measured().copy()
    ramp = smoothstep(np.linspace(0.0, 1.0, 24))[:, None]
    commands = np.vstack([rest + ramp * (RAISED - rest), np.repeat(RAISED[None], 25, axis=0)])
    states = []
    for n, q in enumerate(commands):
        backend.send(n * CONTROL_DT, q)
        states.append(backend.measured().copy())
    backend.close()
    return first_within(np.array(states), RAISED) - first_within(commands, RAISED)


def test_the_default_law_neither_sags_nor_trails_a_fast_preparation(compose):
    default = instantiate(compose().arm_law)
    assert default.gravity_compensation and default.velocity_feedforward and default.tracking_lag_s == 0.0
    assert sag_after_holding(default) < 0.005
    # the arm arrives with the command; without the velocity reference the kd term brakes it and the
    # joint settles within the tolerance only several ticks later
    assert arrival_delay_ticks(default) <= 1 and arrival_delay_ticks(ROBOT_GRAVITY) >= 4


def test_apply_law_switches_gains_and_restores_the_mjcf_servos():
    backend = MujocoBackend(law=MJCF)
    backend.connect(None)
    act = [backend.model.actuator(n).id for n in ("left_shoulder_pitch_joint", "right_elbow_joint")]
    own = backend.model.actuator_gainprm[act, 0].copy()
    backend.apply_law(ROBOT_PLAIN)
    assert np.allclose(backend.model.actuator_gainprm[act, 0], 60.0)
    assert np.allclose(backend.model.actuator_biasprm[act, 2], -1.5) and not backend.model.body_gravcomp.any()
    backend.apply_law(MJCF)
    assert np.allclose(backend.model.actuator_gainprm[act, 0], own) and backend.model.body_gravcomp.any()
    backend.close()


def test_bad_laws_are_refused():
    with pytest.raises(ValueError, match="both kp and kd"):
        ArmLaw("x", 60.0, None)
    with pytest.raises(ValueError, match=">= 0"):
        ArmLaw("x", -1.0, 1.5)
    with pytest.raises(ValueError, match="tracking_lag_s"):
        ArmLaw("x", 60.0, 1.5, tracking_lag_s=2.0)


def test_the_g1_refuses_a_law_without_gains_in_plain_words():
    from emopose.backends.g1.backend import G1Backend

    with pytest.raises(ValueError, match="arm_law=mjcf is simulator-only"):
        G1Backend(kp=None, kd=None)
