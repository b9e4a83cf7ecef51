"""Background reader of rt/lowstate: keeps the newest valid-CRC state (arms, waist, the IMU's roll,
pitch and yaw) and how old it is.

A LowState_ whose CRC fails is counted and dropped, exactly as the firmware treats a bad LowCmd_;
the backend refuses to start on, and releases the arms after losing, *valid* state only.
Runs in its own thread so the 500 Hz stream never waits on the 50 Hz sender (and vice versa).
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable

import numpy as np

import emopose.backends.g1.wire as wire
from emopose.backends.g1.constants import TOPIC_LOWSTATE
from emopose.backends.g1.dds import DdsSession
from emopose.backends.g1.hg_types import LowState_
from emopose.execution.worker import Worker
from emopose.robot.g1_spec import ARM_MOTORS, WAIST_MOTORS

log = logging.getLogger(__name__)
_ARM = slice(ARM_MOTORS[0], ARM_MOTORS[-1] + 1)
_WAIST = slice(WAIST_MOTORS[0], WAIST_MOTORS[-1] + 1)


class LowStateMonitor:
    def __init__(self, session: DdsSession, now: Callable[[], float]) -> None:
        self._reader = session.reader(TOPIC_LOWSTATE, LowState_)
        self._now = now
        self._lock = threading.Lock()
        self._first = threading.Event()
        self._arm_q: np.ndarray | None = None
        self._waist_q: np.ndarray | None = None
        self._imu_rpy: np.ndarray | None = None
        self._stamp = -np.inf
        self.valid = 0
        self.bad_crc = 0
        self.undecodable = 0
        self._worker = Worker("g1-lowstate", self._run, join_timeout_s=1.0)

    def start(self) -> None:
        self._worker.start()

    def stop(self) -> None:
        self._worker.stop()

    def wait_first(self, timeout_s: float) -> bool:
        return self._first.wait(timeout_s)

    def arm_q(self) -> np.ndarray | None:
        with self._lock:
            return None if self._arm_q is None else self._arm_q.copy()

    def waist_q(self) -> np.ndarray | None:
        with self._lock:
            return None if self._waist_q is None else self._waist_q.copy()

    def torso(self) -> tuple[np.ndarray, np.ndarray] | None:
        """(waist yaw, roll, pitch), (IMU roll, pitch, yaw) of the same state; None before the first."""
        with self._lock:
            return None if self._waist_q is None else (self._waist_q.copy(), self._imu_rpy.copy())

    def age(self) -> float:
        """Seconds since the newest valid state arrived (inf before the first one)."""
        with self._lock:
            return self._now() - self._stamp

    def _run(self, stop: threading.Event) -> None:
        while not stop.is_set():
            try:
                samples = self._reader.take(timeout_s=0.05)
            except Exception:  # the participant was deleted under us during close()
                if not stop.is_set():
                    log.exception("reading %s failed", TOPIC_LOWSTATE)
                return
            # Newest first: one valid state per wake-up is all the backend needs.
            for data in reversed(samples):
                record = wire.lowstate_from_cdr(data)
                if record is None:
                    self.undecodable += 1
                    continue
                if not wire.crc_ok(record):
                    self.bad_crc += 1
                    continue
                self._accept(record)
                break

    def _accept(self, record: np.ndarray) -> None:
        q = record["motor_state"]["q"]
        with self._lock:
            self._arm_q = q[_ARM].astype(float)
            self._waist_q = q[_WAIST].astype(float)
            self._imu_rpy = record["imu_state"]["rpy"].astype(float)
            self._stamp = self._now()
            self.valid += 1
        self._first.set()
