"""What every backend is: the sequencer's 50 Hz loop sends it one 14-DoF target per control tick.

Targets are in the library's joint order (emopose.robot.g1_spec.JOINT_NAMES: left arm 0-6,
right arm 7-13). Heavy imports (mujoco, cyclonedds) happen in connect(), never at module import,
so dry-run and unit tests stay fast. What only some backends can do (simulated state, rendering,
a planar base) is declared by the small protocols in emopose.backends.capabilities, which callers
check with isinstance.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import ClassVar

import numpy as np

from emopose.recording import Recorder


class Backend(ABC):
    name: ClassVar[str]
    # True: the loop must run on the wall clock (a real robot); False: virtual time is allowed.
    realtime: ClassVar[bool] = False
    # How long the joints trail the commanded stream (s): motors under their control law. The timeline
    # plans strokes this much ahead; a backend without actuators (dry run) has none.
    tracking_lag_s: float = 0.0
    # True: measured() reads the joints (a simulator's state, the robot's LowState), so the STROKE event
    # comes from them (execution/stroke_watch.py); False: measured() echoes the command (dry run).
    measures_joints: ClassVar[bool] = False
    # How far ahead of the send time the pose measured right after send() stands (a simulator that
    # stepped one period of physics in send(): CONTROL_DT; a robot's latest state: 0).
    measured_lead_s: ClassVar[float] = 0.0

    @abstractmethod
    def connect(self, recorder: Recorder | None) -> np.ndarray | None:
        """Open the connection; return the measured 14-DoF pose to start from, or None when the
        backend cannot measure or has not been placed yet (MuJoCo without `initial_pose` is placed
        at the stream's first command): the run then starts from the library's neutral pose."""

    @abstractmethod
    def send(self, t: float, q: np.ndarray) -> np.ndarray:
        """Command the (14,) target q at stream time t (seconds since the stream started); return what
        was actually sent (q clamped to the backend's limits), the command the loop records."""

    @abstractmethod
    def measured(self) -> np.ndarray | None:
        """The latest measured (14,) joint positions, or None if the backend cannot measure."""

    @property
    @abstractmethod
    def is_connected(self) -> bool:
        """Between a successful connect() and close() (or a fault): send() is accepted."""

    @abstractmethod
    def close(self) -> None:
        """Release the hardware or simulator; safe to call twice."""
