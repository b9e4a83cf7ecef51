"""G1Backend: the sequencer's 14-DoF arm targets to the physical G1 over DDS (rt/arm_sdk).

connect() waits for a valid-CRC rt/lowstate, takes the measured arm pose, and ramps the arm_sdk
weight 0 -> 1 while holding it (never a jump); until the first send() the supervisor thread keeps
holding that pose at 50 Hz. send() clamps and publishes one LowCmd_ per tick. close(), or the
supervisor on a fault (lowstate lost, send() silent past the deadman), blends the targets to the
neutral pose, ramps the weight back to 0 and stops publishing. After a fault the backend is
failed: send() raises G1BackendError with the reason. close() is idempotent and thread-safe.
The parts: Lifecycle (every state transition), ArmOutput (every LowCmd_ out, paced, recorded),
Handover (ramps and release), Supervisor (the watchdog, through the narrow Supervised interface
this class implements: vitals(), hold(), fail()). cyclonedds is imported in connect() only, so
building the backend from config stays cheap.
"""

from __future__ import annotations

import logging
import threading
from typing import TYPE_CHECKING

import numpy as np

from emopose.backends.base import Backend
from emopose.backends.g1.errors import G1BackendError
from emopose.backends.g1.handover import Handover
from emopose.backends.g1.lifecycle import ACTIVE, ArmState, Lifecycle
from emopose.backends.g1.output import ArmOutput
from emopose.backends.g1.settings import G1Settings
from emopose.backends.g1.supervisor import Supervisor, Vitals
from emopose.clock import Clock, MonotonicClock
from emopose.recording import Recorder
from emopose.robot.g1_spec import NUM_JOINTS

if TYPE_CHECKING:
    from emopose.backends.g1.link import G1Link  # imports cyclonedds: only in connect()

log = logging.getLogger(__name__)


class G1Backend(Backend):
    name = "g1"
    realtime = True  # a real robot: the loop runs on the wall clock, never virtual time
    measures_joints = True  # LowState's arm joints

    def __init__(
        self,
        domain_id: int = 0,
        network_interface: str | None = None,
        lowstate_timeout_s: float = 2.0,
        lowstate_loss_ms: float = 200.0,
        kp: float | list[float] | None = 60.0,
        kd: float | list[float] | None = 1.5,
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
        velocity_feedforward: bool = False,
        gravity_compensation: bool = False,
        tracking_lag_s: float = 0.0,
        clock: Clock | None = None,
    ) -> None:
        if kp is None or kd is None:  # arm_law=mjcf: the simulator's own servos have no gains to send
            raise ValueError("g1 backend: the arm law gives no kp/kd (arm_law=mjcf is simulator-only); "
                             "use arm_law=robot, robot_gravity or robot_plain")
        self.tracking_lag_s = tracking_lag_s
        self.settings = G1Settings.build(
            **{k: v for k, v in locals().items() if k not in ("self", "clock", "tracking_lag_s")}
        )
        self._clock = clock or MonotonicClock()
        self._life = Lifecycle()
        self._close_lock = threading.Lock()  # close() calls run one at a time
        self._link: G1Link | None = None
        self._out: ArmOutput | None = None
        self._handover: Handover | None = None
        self._supervisor: Supervisor | None = None
        self._last_send = -np.inf

    # ----------------------------------------------------------------- Backend protocol
    def connect(self, recorder: Recorder | None) -> np.ndarray:
        self._life.start_connect()
        try:
            hold = self._open(recorder)
            self._handover.ramp_up()
        except BaseException:
            self._abort_connect()
            raise
        self._life.connected()
        s = self.settings
        self._supervisor = Supervisor(self, self._clock, s.lowstate_loss_s, s.deadman_s)
        self._supervisor.start()
        return hold.copy()

    def send(self, t: float, q: np.ndarray) -> np.ndarray:
        """Publish q clamped to the joint limits; returns the clamped targets."""
        q = np.asarray(q, dtype=float)
        if q.shape != (NUM_JOINTS,) or not np.all(np.isfinite(q)):
            raise ValueError(
                f"g1 backend: send() needs {NUM_JOINTS} finite joint targets, got {q!r}"
            )
        clamped = np.clip(q, self.settings.lower, self.settings.upper)  # the robot edge re-checks
        with self._life.lock:
            self._life.stream()
            self._out.publish(
                clamped, 1.0, "stream", t=t, clamped=bool(np.any(clamped != q))
            )
            self._last_send = self._clock.now()
        return clamped

    def measured(self) -> np.ndarray | None:
        link = self._link
        return None if link is None else link.monitor.arm_q()

    @property
    def is_connected(self) -> bool:
        """Under SDK weight and taking commands (holding or streaming); False after a fault."""
        return self._life.state in ACTIVE

    def close(self) -> None:
        with self._close_lock:
            try:
                if self._life.claim_release():
                    self._handover.release(reason=None)
                elif self._life.state is ArmState.RELEASING:  # the supervisor is handing back
                    self._life.wait_released()
            finally:
                self._teardown()

    # ------------------------------------------------------------------ diagnostics
    @property
    def state(self) -> ArmState:
        """A StrEnum: compares equal to its value ("streaming", ...)."""
        return self._life.state

    @property
    def failure(self) -> str | None:
        return self._life.failure

    def status(self) -> dict:
        link, out = self._link, self._out
        return {
            "state": self.state.value,
            "failure": self.failure,
            "weight": out.weight if out else 0.0,
            "lowstate_valid": link.monitor.valid if link else 0,
            "lowstate_bad_crc": link.monitor.bad_crc if link else 0,
            "lowstate_age_s": link.state_age() if link else float("inf"),
        }

    # ------------------------------------------------------------------ Supervised
    def vitals(self) -> Vitals:
        with self._life.lock:
            state, link = self._life.state, self._link
            if state not in ACTIVE or link is None:
                return Vitals(state, float("inf"), float("inf"), "")
            return Vitals(
                state, link.state_age(), self._clock.now() - self._last_send, link.where()
            )

    def hold(self) -> None:
        with self._life.lock:
            if self._life.state is ArmState.HOLDING:
                self._out.publish(self._out.last.q, 1.0, "hold")

    def fail(self, reason: str) -> None:
        if not self._life.claim_release(fault=reason):
            return  # close() or another fault has the release
        log.error("g1 backend fault, releasing the arms: %s", reason)
        try:
            self._handover.release(reason)
        except Exception:
            log.exception("release after fault failed")

    # ------------------------------------------------------------------ internals
    def _open(self, recorder: Recorder | None) -> np.ndarray:
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
        self._link.reset_feedforward(hold)  # the first ramp tick's dq* is 0, even from outside the limits
        # No configured neutral pose: hand back where the firmware had the arms.
        neutral = hold.copy() if s.neutral_pose is None else s.neutral_pose
        self._out = ArmOutput(self._link, self._clock, recorder, hold)
        self._handover = Handover(s, self._clock, self._life, self._out, neutral)
        return hold

    def _abort_connect(self) -> None:
        """connect() failed or was interrupted: hand back whatever weight was given, tear down."""
        try:
            gave_weight = self._out is not None and self._out.weight > 0
            if gave_weight and self._life.claim_release(allowed=frozenset({ArmState.RAMPING})):
                self._handover.release(reason="connect() aborted", blend=False)
        finally:
            self._teardown()

    def _teardown(self) -> None:
        if self._supervisor is not None:
            self._supervisor.stop()
        if self._link is not None:
            self._link.close()
        with self._life.lock:
            self._link = None
        self._life.closed()
