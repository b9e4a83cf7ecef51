"""MuJoCo backend: the physics of the project's G1 upper-body model under position servos, 50 Hz.

Each send(t, q) is one control period: the 14 targets become the servos' setpoints and physics
advances CONTROL_DT in `substeps` steps. The servos follow the arm law (emopose/robot/arm_law.py,
conf/arm_law/): by default the law the G1 is sent (kp 60, kd 1.5, with the gravity and velocity
feed-forwards), so the arms track as the robot's do (`arm_law=robot_plain`: sag and lag); `arm_law=mjcf`
restores the MJCF's stiffer servos, gravity compensated through the actuators (body gravcomp + joint
actuatorgravcomp, so the compensating torque shares each joint's torque limit), tracking (q, dq) with
dq the stream's finite difference. `apply_law()` switches laws on a connected model (sim_suite
compares them). Streams written to the Recorder (the control
loop records the commanded stream, /joints/command, itself):
  /joints/sim      {"t", "q"}  the simulated pose at the end of that period, stamped t + CONTROL_DT
  /joints/torque   {"t", "tau", "ratio"}  joint torque (servo + gravcomp) and max |tau|/limit
Attached parts, each built from its own config node: `renderer` (SimRenderer: on-demand images,
live frames, video) and `planar_base` (MujocoPlanarBase: the tour's base, or None).
"""

from __future__ import annotations

import logging
import math
import os
import threading
from dataclasses import replace
from typing import Any

import numpy as np

from emopose.backends.base import Backend
from emopose.backends.planar_base import MujocoPlanarBase
from emopose.backends.sim_renderer import SimRenderer
from emopose.recording import Recorder, joint_state
from emopose.robot.arm_law import ArmLaw
from emopose.robot.feedforward import Feedforward, GravityModel
from emopose.robot.g1_spec import CONTROL_DT, JOINT_NAMES, NUM_JOINTS
from emopose.robot.model import build_model

log = logging.getLogger(__name__)


class MujocoBackend(Backend):
    """Satisfies capabilities.SimulatedState and capabilities.Renderable."""

    name = "mujoco"
    measures_joints = True
    measured_lead_s = CONTROL_DT  # send() steps the physics through the period it commands

    def __init__(
        self,
        model_path: str | None = None,
        substeps: int | None = None,
        timestep: float | None = None,
        initial_pose: list[float] | None = None,
        law: ArmLaw | None = None,
        tracking_lag_s: float = 0.0,
        renderer: SimRenderer | None = None,
        planar_base: MujocoPlanarBase | None = None,
        viewer: bool = False,
    ) -> None:
        if substeps is not None and timestep is not None:
            raise ValueError("mujoco backend: give either substeps or timestep, not both")
        if initial_pose is not None and len(initial_pose) != NUM_JOINTS:
            raise ValueError(
                f"mujoco backend: initial_pose needs {NUM_JOINTS} values, got {len(initial_pose)}"
            )
        self.model_path = model_path
        self.substeps, self.timestep = substeps, timestep
        # None: like dry_run, the run starts from the library's neutral pose (the session's stream start);
        # the arms are placed at the stream's first command, so nothing moves from a pose nobody chose.
        self.initial_pose = None if initial_pose is None else np.asarray(initial_pose, float)
        # Built without a law (code, not config): the servos as the model file declares them.
        self.law = law or ArmLaw("mjcf", None, None, velocity_feedforward=True, gravity_compensation=True)
        self.tracking_lag_s = tracking_lag_s
        self.renderer = renderer or SimRenderer()  # on-demand frames only, unless configured
        self.planar_base = planar_base
        self.viewer = viewer
        self.max_actuator_force_ratio = 0.0
        self.n_substeps: int | None = None
        self.model = self.data = None
        self._recorder: Recorder | None = None
        self._lock = threading.RLock()
        self._viewer = None
        self._tick = 0
        self._placed = False  # the arms stand where a caller (initial_pose, reset, first send) put them
        self._connected = False

    def select_gl(self) -> bool:
        """mujoco reads MUJOCO_GL at its first import: glfw for the viewer window, else egl."""
        want_viewer = self.viewer and bool(os.environ.get("DISPLAY"))
        if self.viewer and not want_viewer:
            log.warning("mujoco backend: viewer requested but no DISPLAY; running headless")
        os.environ.setdefault("MUJOCO_GL", "glfw" if want_viewer else "egl")
        return want_viewer

    # -- Backend ---------------------------------------------------------------------------------
    def connect(self, recorder: Recorder | None) -> np.ndarray:
        want_viewer = self.select_gl()
        import mujoco

        self._mj = mujoco
        self.model = build_model(self.model_path, planar_base=self.planar_base is not None)
        # A whole number of physics steps fills each control period (timestep rounded down to fit).
        dt = self.timestep if self.timestep is not None else self.model.opt.timestep
        self.n_substeps = self.substeps or max(1, math.ceil(CONTROL_DT / dt - 1e-9))
        self.model.opt.timestep = CONTROL_DT / self.n_substeps
        if self.model.opt.timestep > 0.002 + 1e-12:
            raise ValueError(
                f"mujoco backend: timestep {self.model.opt.timestep} s is coarser than 2 ms (500 Hz)"
            )
        self.data = mujoco.MjData(self.model)
        m = self.model
        joints = [m.joint(n) for n in JOINT_NAMES]
        self._qadr = np.array([j.qposadr[0] for j in joints])
        self._dadr = np.array([j.dofadr[0] for j in joints])
        self._act = np.array([m.actuator(n).id for n in JOINT_NAMES])
        self._lo, self._hi = m.jnt_range[[j.id for j in joints]].T
        self._tau_limit = m.jnt_actfrcrange[[j.id for j in joints], 1]
        self._mjcf_servos = (m.actuator_gainprm[self._act, 0].copy(),
                             -m.actuator_biasprm[self._act, 2].copy())
        self._mjcf_gravcomp = (m.body_gravcomp.copy(), m.jnt_actgravcomp.copy())
        self._gravity: GravityModel | None = None  # built the first time a law asks for a gravity torque
        self.apply_law(self.law)
        self._placed = False
        if self.initial_pose is not None:
            self._place(self.initial_pose)
        self._recorder, self._tick = recorder, 0
        self.max_actuator_force_ratio = 0.0
        self.renderer.attach(m, self.data, self._lock)
        if self.planar_base is not None:
            self.planar_base.attach(m, self.data, self._lock)
        if want_viewer:
            import mujoco.viewer

            self._viewer = mujoco.viewer.launch_passive(m, self.data)
        self._connected = True
        return self.measured()  # None until placed: the session then starts from the library's neutral

    def send(self, t: float, q: np.ndarray) -> np.ndarray:
        """One control period of physics toward q clipped to the joints' ranges; returns that target."""
        if self.data is None:
            raise RuntimeError("mujoco backend: send() before connect()")
        target = np.clip(np.asarray(q, dtype=float).reshape(NUM_JOINTS), self._lo, self._hi)
        if not self._placed:
            self._place(target)
        dq, tau = self._feedforward(target)
        # A position servo makes kp (ctrl - q) - kv qd, so the robot's kp (q* - q) + kd (dq* - qd) + tau_ff
        # is ctrl = q* + (kd dq* + tau_ff) / kp.
        setpoint = target + (self._kv * dq + tau) / self._kp
        with self._lock:
            self.data.ctrl[self._act] = setpoint
            ratio = 0.0
            for _ in range(self.n_substeps):
                self._mj.mj_step(self.model, self.data)
                tau = self.data.qfrc_actuator[self._dadr]
                ratio = max(ratio, float(np.max(np.abs(tau) / self._tau_limit)))
            q_sim, dq_sim = self.data.qpos[self._qadr].copy(), self.data.qvel[self._dadr].copy()
        self.max_actuator_force_ratio = max(self.max_actuator_force_ratio, ratio)
        self._tick += 1
        if self._recorder is not None:
            t_sim = t + CONTROL_DT
            self._recorder.write("/joints/sim", t_sim, {"q": q_sim.tolist()})  # the recorder stamps t
            self._recorder.write("/joints/torque", t_sim, {"tau": tau.tolist(), "ratio": ratio})
            self._recorder.write("/joint_states", t_sim, joint_state(q_sim, dq_sim, tau))
        self.renderer.after_tick(self._tick)
        if self._viewer is not None and self._viewer.is_running():
            self._viewer.sync()
        return target

    def apply_law(self, law: ArmLaw) -> None:
        """Servo gains and feed-forwards of `law`. Without gains it keeps the MJCF's own servos, whose
        gravity compensation the model applies itself (body gravcomp) instead of a tau_ff."""
        m = self.model
        own = law.model_servos
        kp, kv = self._mjcf_servos if own else (law.gains(law.kp), law.gains(law.kd))
        with self._lock:
            m.actuator_gainprm[self._act, 0] = kp  # position servo: kp (ctrl - q) - kv dq
            m.actuator_biasprm[self._act, 1] = -kp
            m.actuator_biasprm[self._act, 2] = -kv
            builtin = own and law.gravity_compensation
            bodies, joints = self._mjcf_gravcomp
            m.body_gravcomp[:] = bodies if builtin else 0.0
            m.jnt_actgravcomp[:] = joints if builtin else 0
        self._kp, self._kv = np.maximum(kp, 1e-9), kv
        fed = replace(law, gravity_compensation=False) if own else law
        if fed.gravity_compensation and self._gravity is None:
            self._gravity = GravityModel(self.model_path)
        self._feedforward = Feedforward(fed, self._gravity)
        self._feedforward.reset(self.data.qpos[self._qadr])
        self.law = law

    def reset(self, q: np.ndarray) -> np.ndarray:
        """Put the arms at rest at q (clipped to range) with the servos holding it: lets library
        checks and replays start each run from a known pose without reconnecting."""
        if self.data is None:
            raise RuntimeError("mujoco backend: reset() before connect()")
        with self._lock:
            self._mj.mj_resetData(self.model, self.data)
            self._place(q)
        self.max_actuator_force_ratio = 0.0
        return self.measured()

    def _place(self, q: np.ndarray) -> None:
        """The arms at rest at q (clipped to range), the servos holding it; the rest of the state as is."""
        q = np.clip(np.asarray(q, dtype=float).reshape(NUM_JOINTS), self._lo, self._hi)
        with self._lock:
            self.data.qpos[self._qadr] = q
            self.data.qvel[self._dadr] = 0.0
            self.data.ctrl[self._act] = q
            self._mj.mj_forward(self.model, self.data)
        self._feedforward.reset(q)
        self._placed = True

    def measured(self) -> np.ndarray | None:
        """The simulated arm pose; None before connect() or (no initial_pose) before the first command."""
        if self.data is None or not self._placed:
            return None
        with self._lock:
            return self.data.qpos[self._qadr].copy()

    @property
    def is_connected(self) -> bool:
        return self._connected

    def close(self) -> None:
        self._connected = False
        self.renderer.close()
        if self._viewer is not None:
            self._viewer.close()
            self._viewer = None

    # -- SimulatedState, Renderable ---------------------------------------------------------------
    def render_frame(self, camera: Any = None) -> np.ndarray:
        return self.renderer.render_frame(camera)

    def contacts(self) -> list[tuple[str, str]]:
        """Geom-name pairs of current contacts between two robot geoms (the floor is not robot)."""
        m, d = self.model, self.data
        pairs = set()
        with self._lock:
            for c in d.contact[: d.ncon]:
                if m.geom_bodyid[c.geom1] == 0 or m.geom_bodyid[c.geom2] == 0:
                    continue
                pairs.add(tuple(sorted((m.geom(c.geom1).name, m.geom(c.geom2).name))))
        return sorted(pairs)

    def joint_torques(self) -> np.ndarray:
        """Current (14,) joint torques: servo plus gravity compensation, N m."""
        with self._lock:
            return self.data.qfrc_actuator[self._dadr].copy()
