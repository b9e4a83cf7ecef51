"""The release plan: the arms handed back to the firmware in bounded time, with no step in the torque
the feed-forwards add.

A release starts from the last command sent (pose q, weight w0, feed-forwards dq* and tau) and runs one
command per tick: the targets blend to the hand-back pose at weight w0 (release_blend_s), then the
weight ramps to 0 holding it (w0 * weight_ramp_down_s). Along the way
  dq* = the blend's own velocity (under the velocity feed-forward) + the last command's dq*, faded out
        with the half-cosine (a fault mid-motion no longer drops it to 0 in one tick);
  tau = G(q*) scaled by w / w0 (under gravity compensation): it reaches 0 with the weight.
The bound: between two commands (the last one before the release and the first of it included), no
joint's kd * dq* + tau, what the feed-forwards add to the motor's torque, changes by more than
MAX_EFFORT_STEP_NM. 0.5 N m is 2 % of the arm motors' 25 N m limit and 1/12 of the largest velocity
term (kd 1.5 x the 4 rad/s cap), which therefore fades over at least 38 ticks (0.76 s). The plan is
measured before it runs; where it exceeds the bound (short configured ramps, a steep gravity torque),
all its phases are stretched 2x, 4x, then 8x (MAX_STRETCH) until it holds: a release never takes longer
than MAX_STRETCH x (its configured length, or the fade's). With the default settings (2 s blend, 3 s
ramp) it is not stretched at all.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from emopose.backends.g1.profiles import blend_ticks, n_steps, ramp_ticks, smooth
from emopose.robot.feedforward import MAX_VELOCITY_REFERENCE

log = logging.getLogger(__name__)

MAX_EFFORT_STEP_NM = 0.5  # per tick and joint, of kd * dq* + tau, in every release
MAX_STRETCH = 8


@dataclass(frozen=True)
class Command:
    """One LowCmd_'s arm part: targets, weight and the two feed-forwards."""

    q: np.ndarray
    weight: float
    dq: np.ndarray
    tau: np.ndarray


@dataclass(frozen=True)
class FeedLaw:
    """What the feed-forwards of a release follow: kd, and which terms the arm law sends."""

    kd: np.ndarray
    velocity_feedforward: bool
    gravity: Callable[[np.ndarray], np.ndarray] | None  # G(q), None without gravity compensation
    dt: float


@dataclass(frozen=True)
class ReleasePlan:
    q: np.ndarray  # (n, 14)
    weight: np.ndarray  # (n,)
    dq: np.ndarray  # (n, 14)
    tau: np.ndarray  # (n, 14)

    def __len__(self) -> int:
        return len(self.weight)

    def commands(self) -> list[Command]:
        return [Command(*row) for row in zip(self.q, self.weight, self.dq, self.tau)]

    def effort_step(self, start: Command, kd: np.ndarray) -> float:
        """The largest change of kd * dq* + tau between consecutive commands, from `start` on (N m)."""
        effort = np.vstack([kd * start.dq + start.tau, kd * self.dq + self.tau])
        return float(np.abs(np.diff(effort, axis=0)).max()) if len(self) else 0.0


def plan_release(start: Command, target: np.ndarray, blend_s: float, ramp_down_s: float,
                 law: FeedLaw) -> ReleasePlan:
    """The release from `start` to `target` (the neutral pose) within the bound, stretched in time where
    the configured durations would exceed it. blend_s 0: no blend, the arms are handed back in place."""
    if blend_s <= 0:
        target = start.q
    n_blend = n_steps(blend_s, law.dt) if not np.array_equal(target, start.q) else 0
    n_ramp = n_steps(start.weight * ramp_down_s, law.dt)
    fade_span = float(np.max(np.abs(law.kd * start.dq)))
    n_fade = max(n_blend, math.ceil(math.pi * fade_span / MAX_EFFORT_STEP_NM), 1)  # half the bound
    stretch = 1
    while True:
        plan = _build(start, target, n_blend * stretch, n_ramp * stretch, n_fade * stretch, law)
        step = plan.effort_step(start, law.kd)
        if step <= MAX_EFFORT_STEP_NM:
            return plan
        if stretch >= MAX_STRETCH:
            log.warning("release: the feed-forwards change by up to %.2f N m a tick (bound %.2f N m) "
                        "even stretched %dx", step, MAX_EFFORT_STEP_NM, stretch)
            return plan
        stretch *= 2


def _build(start: Command, target: np.ndarray, n_blend: int, n_ramp: int, n_fade: int,
           law: FeedLaw) -> ReleasePlan:
    n_ramp = max(n_ramp, n_fade - n_blend, 1)  # the weight reaches 0 last, after the fade
    poses = np.vstack([blend_ticks(start.q, target, n_blend) if n_blend else np.empty((0, len(target))),
                       np.repeat(target[None, :], n_ramp, axis=0)])
    weights = np.concatenate([np.full(n_blend, start.weight), ramp_ticks(start.weight, 0.0, n_ramp)])
    n = len(weights)
    fade = smooth(np.arange(1, n + 1) / n_fade)[:, None]
    dq = (1.0 - fade) * start.dq[None, :]
    if law.velocity_feedforward:
        velocity = np.diff(np.vstack([start.q, poses]), axis=0) / law.dt
        dq = dq + np.clip(velocity, -MAX_VELOCITY_REFERENCE, MAX_VELOCITY_REFERENCE)
    tau = np.zeros_like(poses)
    if law.gravity is not None and start.weight > 0:
        held = law.gravity(target)
        blending = [law.gravity(q) for q in poses[:n_blend]]
        gravity = np.vstack([*blending, np.repeat(held[None], n_ramp, 0)])
        tau = gravity * (weights / start.weight)[:, None]
    return ReleasePlan(poses, weights, dq, tau)
