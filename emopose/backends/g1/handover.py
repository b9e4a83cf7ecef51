"""Handing the arms to the SDK and back: the weight ramp-up at connect, the release sequence.

Both directions move only smoothly: the weight follows profiles.ramp, the targets profiles.blend,
one LowCmd_ per 20 ms tick on absolute deadlines, each through the backend's ArmOutput under the
lifecycle lock. The release runs on whichever thread claimed it (close() or the supervisor).
"""

from __future__ import annotations

import logging

import numpy as np

from emopose.backends.g1.constants import TOPIC_LOWSTATE
from emopose.backends.g1.errors import G1ConnectionError
from emopose.backends.g1.lifecycle import Lifecycle
from emopose.backends.g1.output import ArmOutput
from emopose.backends.g1.profiles import ramp, release_plan
from emopose.backends.g1.settings import G1Settings
from emopose.clock import Clock
from emopose.robot.g1_spec import CONTROL_DT

log = logging.getLogger(__name__)


class Handover:
    def __init__(
        self,
        settings: G1Settings,
        clock: Clock,
        life: Lifecycle,
        output: ArmOutput,
        neutral: np.ndarray,
    ) -> None:
        self._settings, self._clock, self._life = settings, clock, life
        self._out, self._neutral = output, neutral

    def ramp_up(self) -> None:
        """Weight 0 -> 1 while holding the measured pose; lost state on the way refuses the start."""
        s, out = self._settings, self._out
        hold = out.last_q.copy()
        deadline = self._clock.now()
        for w in ramp(0.0, 1.0, s.weight_ramp_up_s, CONTROL_DT):
            deadline += CONTROL_DT
            self._clock.sleep_until(deadline)
            if out.link.state_age() > s.lowstate_loss_s:
                raise G1ConnectionError(
                    f"lost {TOPIC_LOWSTATE} while ramping the arm_sdk weight up "
                    f"({out.link.where()})"
                )
            with self._life.lock:
                out.publish(hold, float(w), "ramp_up")

    def release(self, reason: str | None, blend: bool = True) -> None:
        """Blend to neutral, ramp the weight to 0, stop; the caller claimed the release. A Ctrl-C
        during the few-second hand-back is held until it is done: stopping half-way would leave
        the arms under SDK weight with nobody commanding them."""
        s, out = self._settings, self._out
        out.record("/g1/event", {"event": "release", "reason": reason, "weight": out.weight})
        poses, weights = release_plan(
            out.last_q.copy(),
            self._neutral,
            out.weight,
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
                with self._life.lock:
                    out.publish(q, float(w), "release")
            except KeyboardInterrupt as exc:
                interrupted = exc
            except Exception:
                log.exception("publishing the release sequence failed; stopping it")
                break
        self._life.released()
        if interrupted is not None:
            raise interrupted
