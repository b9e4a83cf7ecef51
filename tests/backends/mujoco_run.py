"""Driving a MujocoBackend tick by tick in the tests, as the control loop would."""

from __future__ import annotations

import numpy as np

from emopose.robot.g1_spec import CONTROL_DT

# Arms hanging relaxed, elbows bent: a pose clear of every self-contact.
NEUTRAL = np.array([0, 0.15, 0, 1.2, 0, 0, 0, 0, -0.15, 0, 1.2, 0, 0, 0])


def run_ticks(backend, targets: np.ndarray) -> np.ndarray:
    """Send each row of targets as one control period; the measured pose after each, (T, 14)."""
    measured = []
    for k, q in enumerate(targets):
        backend.send(k * CONTROL_DT, q)
        measured.append(backend.measured())
    return np.array(measured)
