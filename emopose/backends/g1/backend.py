"""G1Backend: the sequencer's 14-DoF arm targets to the physical G1 over DDS (rt/arm_sdk).

connect() waits for a valid-CRC rt/lowstate, takes the measured arm pose, and ramps the arm_sdk
weight 0 -> 1 while holding it (never a jump); until the first send() the supervisor thread keeps
holding that pose at 50 Hz. send() clamps and publishes one LowCmd_ per tick. close(), or the
supervisor on a fault (lowstate lost, send() silent past the deadman), blends the targets to the
neutral pose, ramps the weight back to 0 and stops publishing. After a fault the backend is
failed: send() raises G1BackendError with the reason. close() is idempotent and thread-safe.
cyclonedds is imported in connect() only, so building the backend from config stays cheap.
"""

from __future__ import annotations

import logging
import threading
import time

import numpy as np

from emopose.backends.base import Backend
from emopose.backends.g1.errors import G1BackendError
from emopose.backends.g1.handover import HandoverMixin
from emopose.backends.g1.settings import G1Settings
from emopose.clock import Clock, MonotonicClock
from emopose.recording import Recorder
from emopose.robot.g1_spec import NUM_JOINTS

log = logging.getLogger(__name__)


class G1Backend(HandoverMixin, Backend):
    name = "g1"
    realtime = True  # a real robot: the loop runs on the wall clock, never virtual time

    def __init__(
        self,
        domain_id: int = 0,
        network_interface: str | None = None,
        lowstate_timeout_s: float = 2.0,
        lowstate_loss_ms: float = 200.0,
        kp: float | list[float] = 60.0,
        kd: float | list[float] = 1.5,
        weight_ramp_up_s: float = 1.0,
        weight_ramp_down_s: float = 3.0,
        release_blend_s: float = 2.0,
        neutral_pose: list[float] | None = None,
        lower: list[float] | None = None,
        upper: list[float] | None = None,
        deadman_ms: float = 100.0,
        command_waist: bool = False,
        waist_kp: float = 60.0,
        waist_kd: float = 1.5,
        clock: Clock | None = None,
    ) -> None:
        self.settings = G1Settings.build(
            **{k: v for k, v in locals().items() if k not in ("self", "clock")}
        )
        self._clock = clock or MonotonicClock()
        self._lock = threading.RLock()  # state, last command and every DDS write
        self._close_lock = threading.Lock()  # close() calls run one at a time
        self._released = threading.Event()  # a release sequence has finished
        self._state = "idle"  # idle ramping holding streaming releasing failed closed
        self._failure: str | None = None
        self._recorder: Recorder | None = None
        self._link = None
        self._supervisor = None
        self._neutral = self.settings.neutral_pose
        self._last_q = np.zeros(NUM_JOINTS)
        self._weight = 0.0
        self._last_send = -np.inf

    # ----------------------------------------------------------------- Backend protocol
    def connect(self, recorder: Recorder | None) -> np.ndarray:
        with self._lock:
            if self._state != "idle":
                raise G1BackendError(
                    f"g1 backend: connect() called twice (backend is {self._state})"
                )
            self._state = "ramping"
        self._recorder = recorder
        try:
            hold = self._open()
            self._ramp_up(hold)
        except BaseException:
            self._abort_connect()
            raise
        from emopose.backends.g1.supervisor import Supervisor

        with self._lock:
            self._state = "holding"
        self._supervisor = Supervisor(self)
        self._supervisor.start()
        return hold.copy()

    def send(self, t: float, q: np.ndarray) -> None:
        q = np.asarray(q, dtype=float)
        if q.shape != (NUM_JOINTS,) or not np.all(np.isfinite(q)):
            raise ValueError(
                f"g1 backend: send() needs {NUM_JOINTS} finite joint targets, got {q!r}"
            )
        clamped = np.clip(q, self.settings.lower, self.settings.upper)  # the robot edge re-checks
        with self._lock:
            if self._state not in ("holding", "streaming"):
                raise G1BackendError(self._refusal())
            crc = self._publish(clamped, 1.0)
            self._last_send = self._clock.now()
            self._state = "streaming"
        if self._recorder is not None:
            self._recorder.write(
                "/g1/lowcmd",
                t,
                {
                    "q": clamped.tolist(),
                    "weight": 1.0,
                    "crc": crc,
                    "phase": "stream",
                    "clamped": bool(np.any(clamped != q)),
                },
            )

    def measured(self) -> np.ndarray | None:
        link = self._link
        return None if link is None else link.monitor.arm_q()

    def close(self) -> None:
        with self._close_lock:
            with self._lock:
                state = self._state
                if state in ("holding", "streaming"):
                    self._state = "releasing"
            try:
                if state in ("holding", "streaming"):
                    self.release(reason=None)
                elif state == "releasing":  # the supervisor is handing the arms back: let it finish
                    self._released.wait()
            finally:
                self._teardown()

    # ------------------------------------------------------------------ diagnostics
    @property
    def state(self) -> str:
        return self._state

    @property
    def failure(self) -> str | None:
        return self._failure

    def status(self) -> dict:
        link = self._link
        return {
            "state": self._state,
            "failure": self._failure,
            "weight": self._weight,
            "lowstate_valid": link.monitor.valid if link else 0,
            "lowstate_bad_crc": link.monitor.bad_crc if link else 0,
            "lowstate_age_s": link.state_age() if link else float("inf"),
        }

    # ------------------------------------------------------------------ internals
    def _open(self) -> np.ndarray:
        """DDS link up, robot seen; returns the pose to hold: the measured one, clamped."""
        try:
            from emopose.backends.g1.link import G1Link
        except ImportError as exc:
            raise G1BackendError(
                "the g1 backend needs cyclonedds 0.10.2: run .ci/install_cyclonedds.sh "
                f"(or pip install '.[g1]' with CYCLONEDDS_HOME set): {exc}"
            ) from exc
        s = self.settings
        self._link = G1Link(s, self._clock.now)
        measured = self._link.wait_for_robot()
        hold = np.clip(measured, s.lower, s.upper)
        if np.any(hold != measured):
            log.warning(
                "measured arm pose is outside the limits at joints %s; holding the clamped pose "
                "(the weight ramp makes the move gradual)",
                np.flatnonzero(hold != measured).tolist(),
            )
        if self._neutral is None:
            self._neutral = hold.copy()  # hand back where the firmware had the arms
        self._last_q = hold.copy()
        return hold

    def _publish(self, q: np.ndarray, weight: float, phase: str | None = None) -> int:
        """One LowCmd_ out. Caller holds self._lock. Internal phases are recorded here; send()
        records its own message with the sequencer's stream time."""
        crc = self._link.publish(q, weight)
        self._last_q = q
        self._weight = weight
        if phase is not None:
            self._record(
                "/g1/lowcmd", {"q": q.tolist(), "weight": weight, "crc": crc, "phase": phase}
            )
        return crc

    def _record(self, topic: str, payload: dict) -> None:
        if self._recorder is not None:
            self._recorder.write(topic, (time.time_ns() - self._recorder.start_ns) / 1e9, payload)

    def _refusal(self) -> str:
        if self._failure is not None:
            return (
                "g1 backend released the arms after a fault and accepts no more commands: "
                f"{self._failure}"
            )
        if self._state in ("idle", "ramping"):
            return "g1 backend: send() before connect() finished"
        return f"g1 backend is {self._state}; send() is no longer accepted"

    def _teardown(self) -> None:
        if self._supervisor is not None:
            self._supervisor.stop()
        if self._link is not None:
            self._link.close()
        with self._lock:
            self._link = None
            if self._state != "failed":
                self._state = "closed"
