"""What only some backends (or their attached parts) can do, as protocols checked with isinstance.

A caller asks `isinstance(backend, SimulatedState)` instead of probing attributes or comparing
backend names, so a new backend that offers the capability needs no edit at the call sites.
Runtime checks look only for the members' presence; the annotations say what they hold.
  SimulatedState  MujocoBackend: a physics model callers may inspect, re-pose and check
  Renderable      MujocoBackend, SimRenderer: offscreen images of the current state
  FrameSource     SimRenderer (backend.renderer): frames produced while the backend runs
  PlanarBase      MujocoPlanarBase (backend.planar_base): the simulated base the tour drives
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

import numpy as np

from emopose.robot.arm_law import ArmLaw


@runtime_checkable
class PlanarBase(Protocol):
    """A base driven in the plane by velocity commands, like the G1's sport service."""

    def set_velocity(self, vx: float, vy: float, yaw_rate: float) -> None:
        """Body-frame velocity command: m/s forward, m/s left, rad/s counter-clockwise."""

    def pose(self) -> tuple[float, float, float]:
        """Ground truth (x, y, yaw) in the world frame: metres, metres, radians (unwrapped)."""

    def velocity(self) -> tuple[float, float, float]:
        """Ground truth body-frame (vx, vy, yaw rate)."""

    def place(self, x: float, y: float, yaw: float) -> None:
        """Teleport the base, at rest, to (x, y, yaw)."""


@runtime_checkable
class SimulatedState(Protocol):
    """A physics simulation of the robot that callers may inspect and re-pose."""

    model_path: str | None  # the MJCF connect() loads; may be replaced before connect()
    model: Any  # mujoco.MjModel once connected, else None
    data: Any  # mujoco.MjData once connected (the full qpos, base included), else None
    planar_base: PlanarBase | None  # attached by config (the tour's base), else None
    renderer: FrameSource  # the attached renderer: its frames, video and PNG output
    max_actuator_force_ratio: float  # peak |joint torque| / limit since connect(); callers may zero it
    law: ArmLaw  # the arms' motor law its servos apply (emopose/robot/arm_law.py)

    def select_gl(self) -> bool:
        """Choose MUJOCO_GL before mujoco's first import; True when a viewer window will open."""

    def reset(self, q: np.ndarray) -> np.ndarray:
        """Put the arms at rest at q with the servos holding it; returns the measured pose."""

    def contacts(self) -> list[tuple[str, str]]:
        """Sorted geom-name pairs of current contacts between two robot geoms."""

    def joint_torques(self) -> np.ndarray:
        """Current (14,) joint torques, N m."""

    def apply_law(self, law: ArmLaw) -> None:
        """Drive the arms by another motor law from now on (a connected simulator)."""


@runtime_checkable
class Renderable(Protocol):
    """Renders (height, width, 3) uint8 images of the current state offscreen."""

    def render_frame(self, camera: Any = None) -> np.ndarray:
        """camera: an MJCF camera name, a mujoco.MjvCamera, or None for the configured one."""


@runtime_checkable
class FrameSource(Protocol):
    """Produces frames while the backend runs: the latest one, and the files they go to."""

    last_frame: np.ndarray | None
    video_path: str | None
    frames_dir: str | None
