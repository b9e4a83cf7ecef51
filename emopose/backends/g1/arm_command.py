"""Builds the LowCmd_ that goes on rt/arm_sdk: arm targets, arm_sdk weight, gains, CRC.

Only motors 15-28 (and, when asked, the waist 12-14) get mode=1, q, kp, kd, and the arm law's
dq and tau feed-forwards (0 under arm_law=robot_plain, as Unitree's arm example sends them);
motor 29 carries the weight in its q; every other motor stays all-zero so the firmware keeps
the legs. One preallocated record is reused: a command costs a few vectorised assignments,
a ~7 us CRC and a byte copy, which keeps send() far below the 20 ms tick.
"""

from __future__ import annotations

import numpy as np

import emopose.backends.g1.wire as wire
from emopose.robot.g1_spec import ARM_MOTORS, WAIST_MOTORS, WEIGHT_MOTOR

_ARM = slice(ARM_MOTORS[0], ARM_MOTORS[-1] + 1)
_WAIST = slice(WAIST_MOTORS[0], WAIST_MOTORS[-1] + 1)


class ArmCommandBuilder:
    """Not thread-safe: the backend serialises build+write under its publish lock."""

    def __init__(
        self,
        kp: np.ndarray,
        kd: np.ndarray,
        waist_q: np.ndarray | None = None,
        waist_kp: float = 0.0,
        waist_kd: float = 0.0,
    ) -> None:
        self.record = wire.new_lowcmd()
        motors = self.record["motor_cmd"]
        motors["mode"][_ARM] = 1
        motors["kp"][_ARM] = kp
        motors["kd"][_ARM] = kd
        # reserve stays 0; dq and tau are written per command (the arm law's feed-forwards)
        if waist_q is not None:
            motors["mode"][_WAIST] = 1
            motors["q"][_WAIST] = waist_q
            motors["kp"][_WAIST] = waist_kp
            motors["kd"][_WAIST] = waist_kd
        # Views: writes land in the message.
        self._q, self._dq, self._tau = motors["q"], motors["dq"], motors["tau"]

    def build(self, q: np.ndarray, weight: float, dq: np.ndarray | None = None,
              tau: np.ndarray | None = None) -> tuple[bytes, int]:
        """Return (CDR bytes for DataWriter, crc) for arm targets q (14,), weight in [0, 1] and the
        feed-forwards dq, tau (14,) (None: 0)."""
        self._q[_ARM] = q
        self._dq[_ARM] = 0.0 if dq is None else dq
        self._tau[_ARM] = 0.0 if tau is None else tau
        self._q[WEIGHT_MOTOR] = min(max(float(weight), 0.0), 1.0)
        crc = wire.set_crc(self.record)
        return wire.lowcmd_to_cdr(self.record), crc


def decode_arm_command(record: np.ndarray) -> dict:
    """What a receiver needs from a LowCmd_ record: arm q, weight, modes, gains, CRC validity."""
    motors = record["motor_cmd"]
    others = np.ones(len(motors), dtype=bool)
    others[_ARM] = False
    others[_WAIST] = False
    others[WEIGHT_MOTOR] = False
    others_zero = all(not np.any(motors[name][others]) for name in motors.dtype.names)
    return {
        "q": motors["q"][_ARM].astype(float).tolist(),
        "weight": float(motors["q"][WEIGHT_MOTOR]),
        "mode": motors["mode"][_ARM].astype(int).tolist(),
        "kp": motors["kp"][_ARM].astype(float).tolist(),
        "kd": motors["kd"][_ARM].astype(float).tolist(),
        "dq": motors["dq"][_ARM].astype(float).tolist(),
        "tau": motors["tau"][_ARM].astype(float).tolist(),
        "waist_mode": motors["mode"][_WAIST].astype(int).tolist(),
        "waist_q": motors["q"][_WAIST].astype(float).tolist(),
        "others_zero": others_zero,
        "crc_ok": wire.crc_ok(record),
    }
