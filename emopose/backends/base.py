"""What every backend offers the sequencer's 50 Hz loop.

A backend receives one 14-DoF target per control tick, in the library's joint order
(left arm 0-6, right arm 7-13, see library/g1/limits.yaml). Heavy imports (mujoco, cyclonedds)
happen in connect(), never at module import, so dry-run and unit tests stay fast.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

from emopose.recording import Recorder


@runtime_checkable
class Backend(Protocol):
    name: str

    def connect(self, recorder: Recorder | None) -> np.ndarray:
        """Open the connection and return the measured 14-DoF pose to start the first trajectory from."""

    def send(self, t: float, q: np.ndarray) -> None:
        """Command the (14,) target q at stream time t (seconds since the stream started)."""

    def measured(self) -> np.ndarray | None:
        """The latest measured (14,) joint positions, or None if the backend cannot measure."""

    def close(self) -> None:
        """Release the hardware or simulator; safe to call twice."""
