"""The arm law's feed-forward terms for a commanded stream: dq* and tau_ff per 50 Hz target.

One object per stream, used alike by the G1 backend (into LowCmd_'s dq and tau) and by MuJoCo (as a
setpoint offset of its position servos), so the simulator applies exactly what the robot is sent:
  dq*    = the stream's finite difference, capped (law.velocity_feedforward), else 0;
  tau_ff = the gravity torque G(q*) of the project's MJCF at the commanded pose
           (law.gravity_compensation), else 0. The model's masses come from g1.md's figures.
"""

from __future__ import annotations

import numpy as np

from emopose.robot.arm_law import ArmLaw
from emopose.robot.g1_spec import CONTROL_DT, JOINT_NAMES, NUM_JOINTS

MAX_VELOCITY_REFERENCE = 4.0  # rad/s: a step command must not become a velocity spike


class GravityModel:
    """G(q) for the 14 arm joints, from the packaged MJCF (fixed base), at zero velocity."""

    def __init__(self, model_path: str | None = None) -> None:
        import mujoco

        from emopose.robot.model import build_model

        self._mj = mujoco
        self.model = build_model(model_path, meshes=False)  # physics only: no visuals to compile
        self.data = mujoco.MjData(self.model)
        joints = [self.model.joint(n) for n in JOINT_NAMES]
        self._qadr = np.array([j.qposadr[0] for j in joints])
        self._dadr = np.array([j.dofadr[0] for j in joints])

    def __call__(self, q: np.ndarray) -> np.ndarray:
        d = self.data
        d.qpos[self._qadr] = q
        d.qvel[:] = 0.0
        self._mj.mj_kinematics(self.model, d)
        self._mj.mj_comPos(self.model, d)
        out = np.zeros(self.model.nv)
        self._mj.mj_rne(self.model, d, 0, out)  # no acceleration, no velocity: the gravity torque
        return out[self._dadr]


class Feedforward:
    def __init__(self, law: ArmLaw, gravity: GravityModel | None = None, dt: float = CONTROL_DT) -> None:
        self.law, self.dt = law, dt
        self.gravity = gravity if gravity is not None or not law.gravity_compensation else GravityModel()
        self._last: np.ndarray | None = None

    def reset(self, q: np.ndarray) -> None:
        """The stream (re)starts holding q: no velocity reference until it moves."""
        self._last = np.asarray(q, dtype=float).copy()

    def __call__(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(dq*, tau_ff) for the next commanded target q (14,)."""
        q = np.asarray(q, dtype=float)
        dq = np.zeros(NUM_JOINTS)
        if self.law.velocity_feedforward and self._last is not None:
            dq = np.clip((q - self._last) / self.dt, -MAX_VELOCITY_REFERENCE, MAX_VELOCITY_REFERENCE)
        self._last = q.copy()
        tau = self.gravity(q) if self.law.gravity_compensation else np.zeros(NUM_JOINTS)
        return dq, tau
