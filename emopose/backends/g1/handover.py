"""Handing the arms to the SDK and back: the weight ramp-up at connect, the release sequence.

Both directions move only smoothly: the weight rises on a half-cosine (profiles.py), the release follows
its plan (release.py: targets, weight and feed-forwards, bounded per tick). One LowCmd_ per 20 ms tick, paced
by the one deadline policy of every command stream (emopose/execution/pacing.py): after a stall the
missed deadlines are skipped, not sent in a burst, and the ramp goes on with its next step (a step is
never skipped: each tick changes the command by no more than planned). Each command goes through the
backend's ArmOutput under the lifecycle lock. The release runs on whichever thread claimed it (close()
or the supervisor).
"""

from __future__ import annotations

import logging
import math

import numpy as np

from emopose.backends.g1.constants import TOPIC_LOWSTATE
from emopose.backends.g1.errors import G1ConnectionError
from emopose.backends.g1.lifecycle import Lifecycle
from emopose.backends.g1.output import ArmOutput
from emopose.backends.g1.profiles import n_steps, ramp_ticks
from emopose.backends.g1.release import MAX_EFFORT_STEP_NM, plan_release
from emopose.backends.g1.settings import G1Settings
from emopose.clock import Clock
from emopose.execution.pacing import DeadlineGrid
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
        """Weight 0 -> 1 while holding the measured pose; lost state on the way refuses the start.

        The feed-forwards rise with the weight, as a release lowers them (release.py, tau = G(q*) w/w0):
        tau = G(hold) w, so the first command carries almost none and no tick changes kd dq* + tau by more
        than its span max|kd dq* + tau| times sin(pi / 2n) over the ramp's n ticks (0.2 N m with the 1 s
        default and |G| <= 6.3 N m). A configured ramp too short for MAX_EFFORT_STEP_NM is stretched.
        """
        s, out = self._settings, self._out
        hold = out.last.q.copy()
        with self._life.lock:
            dq, tau = out.link.feedforward(hold)  # what full weight will add, planned before the first tick
        n = ramp_up_ticks(s.weight_ramp_up_s, float(np.abs(s.kd * dq + tau).max()))
        grid = DeadlineGrid(self._clock, CONTROL_DT)
        for w in ramp_ticks(0.0, 1.0, n):
            grid.wait()
            if out.link.state_age() > s.lowstate_loss_s:
                raise G1ConnectionError(
                    f"lost {TOPIC_LOWSTATE} while ramping the arm_sdk weight up "
                    f"({out.link.where()})"
                )
            with self._life.lock:
                dq, tau = out.link.feedforward(hold)  # dq* 0 while holding; G under the measured torso
                out.publish(hold, float(w), "ramp_up", feed=(w * dq, w * tau))
            grid.sent()

    def release(self, reason: str | None, blend: bool = True) -> None:
        """Blend to neutral, ramp the weight to 0, stop; the caller claimed the release. blend=False (or
        release_blend_s 0) hands the arms back where they are. A Ctrl-C during the few-second hand-back
        is held until it is done: stopping half-way would leave the arms under SDK weight with nobody
        commanding them."""
        s, out = self._settings, self._out
        blend_s = s.release_blend_s if blend else 0.0
        with self._life.lock:  # the gravity model is the publishers' (they publish under this lock)
            start = out.last
            plan = plan_release(start, self._neutral, blend_s, s.weight_ramp_down_s, out.link.feed_law())
        out.record("/g1/event", {"event": "release", "reason": reason, "weight": start.weight,
                                 "ticks": len(plan), "effort_step_nm": plan.effort_step(start, s.kd)})
        interrupted: BaseException | None = None
        grid = DeadlineGrid(self._clock, CONTROL_DT)
        for command in plan.commands():
            try:
                grid.wait()
            except KeyboardInterrupt as exc:  # finish the hand-back first, re-raise after
                interrupted = exc
            try:
                with self._life.lock:
                    out.publish(command.q, command.weight, "release", feed=(command.dq, command.tau))
                grid.sent()
            except KeyboardInterrupt as exc:
                interrupted = exc
            except Exception:
                log.exception("publishing the release sequence failed; stopping it")
                break
        self._life.released()
        if interrupted is not None:
            raise interrupted


def ramp_up_ticks(configured_s: float, effort_span_nm: float) -> int:
    """Ticks of the weight ramp-up: the configured length, or more where a half-cosine that short would
    step kd dq* + tau (span effort_span_nm at full weight) by more than MAX_EFFORT_STEP_NM in one tick
    (its largest step is span sin(pi / 2n), profiles.max_step). Logged once when stretched."""
    configured = n_steps(configured_s, CONTROL_DT)
    if effort_span_nm <= MAX_EFFORT_STEP_NM:
        return configured
    needed = math.ceil(math.pi / (2 * math.asin(MAX_EFFORT_STEP_NM / effort_span_nm)) - 1e-9)
    if needed > configured:
        log.warning("weight_ramp_up_s %.2f s stretched to %.2f s: the feed-forwards (up to %.2f N m at full "
                    "weight) may change by at most %.2f N m a tick", configured_s, needed * CONTROL_DT,
                    effort_span_nm, MAX_EFFORT_STEP_NM)
    return max(configured, needed)
