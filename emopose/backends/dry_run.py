"""backend=dry_run: no robot; the loop records the 50 Hz command stream to MCAP and this echoes it."""

from __future__ import annotations

import numpy as np

from emopose.backends.base import Backend
from emopose.recording import Recorder


class DryRunBackend(Backend):
    name = "dry_run"

    def __init__(self, initial_pose: list[float] | None = None) -> None:
        self.initial_pose = None if initial_pose is None else np.asarray(initial_pose, dtype=float)
        self.sent = 0
        self._last: np.ndarray | None = None

    def connect(self, recorder: Recorder | None) -> np.ndarray | None:
        """No measurement: the run starts from initial_pose, or from the library's neutral pose if None."""
        self._last = self.initial_pose
        return self.initial_pose

    def send(self, t: float, q: np.ndarray) -> None:
        self._last = q
        self.sent += 1

    def measured(self) -> np.ndarray | None:
        return self._last

    def close(self) -> None:
        pass
