"""MujocoPlanarBase: the tour's base in simulation, attached to a MujocoBackend by config.

With it attached the backend loads the model with slide x, slide y and hinge yaw joints on the
pelvis (emopose.robot.model.build_spec), each driven by a velocity actuator of the same name, so
the base moves like the G1 under its sport service: a body-frame (vx, vy, yaw rate) command.
The tour's odometry, noise and stopping rules live in emopose/tour; this is only the plant.
conf/backend/mujoco.yaml: `planar_base: null`; the tour sets it to this class.
"""

from __future__ import annotations

import math
import threading
from typing import Any

import numpy as np

from emopose.robot.model import BASE_JOINTS


class MujocoPlanarBase:
    def __init__(self) -> None:
        self._model = self._data = None
        self._lock: threading.RLock | None = None

    def attach(self, model: Any, data: Any, lock: threading.RLock) -> None:
        """Bind to a freshly connected simulation (the backend calls this in connect())."""
        self._model, self._data, self._lock = model, data, lock
        self._qadr = [model.joint(n).qposadr[0] for n in BASE_JOINTS]
        self._dadr = [model.joint(n).dofadr[0] for n in BASE_JOINTS]
        self._act = [model.actuator(n).id for n in BASE_JOINTS]

    def _connected(self) -> Any:
        if self._data is None:
            raise RuntimeError("planar base: used before the mujoco backend connected")
        return self._data

    def set_velocity(self, vx: float, vy: float, yaw_rate: float) -> None:
        """Body-frame command, turned into the world-frame slide velocities at the current yaw."""
        d = self._connected()
        with self._lock:
            yaw = d.qpos[self._qadr[2]]
            c, s = np.cos(yaw), np.sin(yaw)  # numpy, as before the split: same bits, same tour
            ctrl = (c * vx - s * vy, s * vx + c * vy, yaw_rate)
            for act, value in zip(self._act, ctrl):
                d.ctrl[act] = value

    def pose(self) -> tuple[float, float, float]:
        d = self._connected()
        with self._lock:
            x, y, yaw = (float(d.qpos[a]) for a in self._qadr)
        return x, y, yaw

    def velocity(self) -> tuple[float, float, float]:
        d = self._connected()
        with self._lock:
            vx_w, vy_w, wz = (float(d.qvel[a]) for a in self._dadr)
            yaw = float(d.qpos[self._qadr[2]])
        c, s = math.cos(yaw), math.sin(yaw)
        return c * vx_w + s * vy_w, -s * vx_w + c * vy_w, wz

    def place(self, x: float, y: float, yaw: float) -> None:
        import mujoco

        d = self._connected()
        with self._lock:
            for adr, value in zip(self._qadr, (x, y, yaw)):
                d.qpos[adr] = value
            for adr in self._dadr:
                d.qvel[adr] = 0.0
            mujoco.mj_forward(self._model, d)
