"""backend=dry_run: no robot; the loop records the 50 Hz command stream to MCAP and this echoes it (an
ideal robot: on /joint_states it is where it was told, at the commands' finite-difference speed)."""

from __future__ import annotations

import numpy as np

from emopose.backends.base import Backend
from emopose.recording import Recorder, joint_state
from emopose.robot.g1_spec import CONTROL_DT


class DryRunBackend(Backend):
    name = "dry_run"

    def __init__(self, initial_pose: list[float] | None = None) -> None:
        self.initial_pose = None if initial_pose is None else np.asarray(initial_pose, dtype=float)
        self.sent = 0
        self._last: np.ndarray | None = None
        self._connected = False
        self._recorder: Recorder | None = None

    def connect(self, recorder: Recorder | None) -> np.ndarray | None:
        """No measurement: the run starts from initial_pose, or from the library's neutral pose if None."""
        self._last, self._recorder = self.initial_pose, recorder
        self._connected = True
        return self.initial_pose

    def send(self, t: float, q: np.ndarray) -> np.ndarray:
        """No limits to clamp to: q goes out as it is."""
        if self._recorder is not None:
            speed = np.zeros_like(q) if self._last is None else (q - self._last) / CONTROL_DT
            self._recorder.write("/joint_states", t, joint_state(q, speed))
        self._last = q
        self.sent += 1
        return q

    def measured(self) -> np.ndarray | None:
        return self._last

    @property
    def is_connected(self) -> bool:
        return self._connected

    def close(self) -> None:
        self._connected = False
