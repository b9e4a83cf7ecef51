"""Handing the arms to the SDK and back: weight ramp-up, release sequence, fault claim.

A mixin of G1Backend (kept in its own module so the backend reads as its public lifecycle).
Both directions move only smoothly: the weight follows profiles.ramp, the targets
profiles.blend, one LowCmd_ per 20 ms tick on absolute deadlines.
"""

from __future__ import annotations

import logging

import numpy as np

from emopose.backends.g1 import profiles
from emopose.backends.g1.constants import TOPIC_LOWSTATE
from emopose.backends.g1.errors import G1ConnectionError
from emopose.robot.g1_spec import CONTROL_DT

log = logging.getLogger("emopose.backends.g1.backend")


class HandoverMixin:
    """Needs from the host: settings, _clock, _lock, _link, _state, _failure, _weight, _last_q,
    _neutral, _released, _publish(), _record(), _teardown()."""

    def _ramp_up(self, hold: np.ndarray) -> None:
        s = self.settings
        deadline = self._clock.now()
        for w in profiles.ramp(0.0, 1.0, s.weight_ramp_up_s, CONTROL_DT):
            deadline += CONTROL_DT
            self._clock.sleep_until(deadline)
            if self._link.state_age() > s.lowstate_loss_s:
                raise G1ConnectionError(
                    f"lost {TOPIC_LOWSTATE} while ramping the arm_sdk weight up "
                    f"({self._link.where()})"
                )
            with self._lock:
                self._publish(hold, float(w), phase="ramp_up")

    def _abort_connect(self) -> None:
        """connect() failed or was interrupted: hand back whatever weight was given, tear down."""
        try:
            if self._weight > 0:
                with self._lock:
                    self._state = "releasing"
                self.release(reason="connect() aborted", blend=False)
        finally:
            self._teardown()

    def fault(self, reason: str) -> bool:
        """Claim the release for a fault; False if someone else (close, another fault) has it."""
        with self._lock:
            if self._state not in ("holding", "streaming"):
                return False
            self._state = "releasing"
            self._failure = reason
        log.error("g1 backend fault, releasing the arms: %s", reason)
        return True

    def release(self, reason: str | None, blend: bool = True) -> None:
        """Blend to neutral, ramp the weight to 0, stop. Runs on the thread that set 'releasing'.
        A Ctrl-C during the few-second hand-back is held until it is done: stopping half-way would
        leave the arms under SDK weight with nobody commanding them."""
        s = self.settings
        self._record("/g1/event", {"event": "release", "reason": reason, "weight": self._weight})
        neutral = self._neutral if self._neutral is not None else self._last_q.copy()
        poses, weights = profiles.release_plan(
            self._last_q.copy(),
            neutral,
            self._weight,
            s.release_blend_s if blend else 0.0,
            s.weight_ramp_down_s,
            CONTROL_DT,
        )
        interrupted: BaseException | None = None
        deadline = self._clock.now()
        for q, w in zip(poses, weights):
            deadline += CONTROL_DT
            try:
                self._clock.sleep_until(deadline)
            except KeyboardInterrupt as exc:  # finish the hand-back first, re-raise after
                interrupted = exc
            try:
                with self._lock:
                    self._publish(q, float(w), phase="release")
            except KeyboardInterrupt as exc:
                interrupted = exc
            except Exception:
                log.exception("publishing the release sequence failed; stopping it")
                break
        with self._lock:
            self._state = "failed" if self._failure is not None else "closed"
        self._released.set()
        if interrupted is not None:
            raise interrupted
