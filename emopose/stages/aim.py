"""Aim stage (conf/pipeline/tour.yaml): retarget pointing gestures at the object they refer to.

Runs after modulate and rewrites `modulated` (the pipeline lets a later stage replace a field).
For each pointing record whose target the scene knows (its SceneSlot, emopose/scene/view.py), the gesture
is mirrored onto the arm on the target's side when needed, and every "peak" keyframe (an interior
keyframe whose arm excursion reaches `peak_fraction` of the largest) is replaced by an IK solution
that aims the hand's pointing axis at the target. The approach and return keyframes stay the
library's. A target the arm cannot aim at exactly gets the closest aim (reported as not converged).
If the aimed keyframes fail the configured self-collision check, the library motion is kept.
Without a scene the stage passes everything through unchanged.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from itertools import pairwise

import numpy as np

from emopose.joint_limits import JointLimits
from emopose.robot.g1_spec import ARM_DOF
from emopose.robot.kinematics import mirror
from emopose.robot.pointing_ik import aim_arm
from emopose.scene.view import SceneSlot
from emopose.stages.modulate import LIMIT_MARGIN
from emopose.turn.model import ModulatedGesture, Turn

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class AimReport:
    gesture: str
    target: str
    side: str
    mirrored: bool
    error_deg: float  # worst over the peak keyframes, by forward kinematics
    converged: bool
    applied: bool
    reason: str = ""


def active_side(keyframes: np.ndarray) -> int:
    """The arm (0 left, 1 right) that moves most away from the first keyframe."""
    excursion = np.abs(keyframes - keyframes[0])
    return int(np.argmax([excursion[:, :ARM_DOF].max(), excursion[:, ARM_DOF:].max()]))


def peak_indices(keyframes: np.ndarray, side: int, fraction: float) -> list[int]:
    arm = keyframes[:, side * ARM_DOF:(side + 1) * ARM_DOF]
    if len(keyframes) < 3:
        return [len(keyframes) - 1]
    excursion = np.linalg.norm(arm[1:-1] - arm[0], axis=1)
    return [k + 1 for k in np.flatnonzero(excursion >= fraction * excursion.max())]


def _densify(keyframes: np.ndarray, per_segment: int = 8) -> np.ndarray:
    """Straight-line samples between keyframes: what the collision check sees of the new poses."""
    parts = [keyframes[:1]]
    for a, b in pairwise(keyframes):
        parts.append(a + np.linspace(0.0, 1.0, per_segment + 1)[1:, None] * (b - a))
    return np.concatenate(parts)


@dataclass
class AimStage:
    """Stage: modulated -> modulated (pointing peaks aimed at the scene's target)."""

    scene: SceneSlot = field(repr=False)
    limits: JointLimits = field(repr=False)
    safety: Callable[[np.ndarray], str | None] | None = field(default=None, repr=False)
    classes: tuple[str, ...] = ("pointing",)
    skip: tuple[str, ...] = ("point_to_self",)  # deictic to the robot itself: never aimed elsewhere
    peak_fraction: float = 0.6
    side_switch_m: float = 0.15  # mirror onto the other arm when the target is this far to its side
    margin: float = LIMIT_MARGIN  # stay this far inside the joint limits, as modulate does
    tolerance_deg: float = 0.3
    abductions: tuple[float, ...] = (0.0, 0.3, 0.6)  # rad of extra shoulder roll to retry with on a collision
    name = "aim"
    reads = ("plan", "modulated")
    writes = ("modulated",)

    def __post_init__(self) -> None:
        if not 0.0 < self.peak_fraction <= 1.0:
            raise ValueError(f"pipeline.stages.aim.peak_fraction must be in (0, 1], got {self.peak_fraction}")
        self.classes, self.skip = tuple(self.classes), tuple(self.skip)
        self.abductions = tuple(float(a) for a in self.abductions) or (0.0,)

    def __call__(self, turn: Turn) -> list[ModulatedGesture]:
        scene = self.scene.view
        if scene is None:
            return list(turn.modulated)
        out = []
        for gesture in turn.modulated:
            record = gesture.resolved.record
            target = None
            aimable = record.cls in self.classes or gesture.resolved.entry.cls in self.classes
            if aimable and gesture.name not in self.skip:
                target = scene.target_for(record.trigger, turn.plan.reply)
            if target is None:
                out.append(gesture)
                continue
            keyframes, report = self.aim(gesture.keyframes, scene.in_torso(target), gesture.name, target.name)
            scene.aims.append(report)
            out.append(replace(gesture, keyframes=keyframes) if report.applied else gesture)
        return out

    def aim(self, keyframes: np.ndarray, target: np.ndarray, gesture: str = "", target_name: str = ""):
        """Aimed (K, 14) keyframes for a torso-frame target, and the report."""
        side = active_side(keyframes)
        wanted = 0 if target[1] > self.side_switch_m else 1 if target[1] < -self.side_switch_m else side
        mirrored = wanted != side
        base = mirror(keyframes) if mirrored else np.array(keyframes, float)  # the limits are mirror images
        safety = self.safety
        for abduction in self.abductions:  # a pose that brushes the torso is retried with the arm further out
            aimed, errors, converged = self._solve(base, wanted, target, self.limits, abduction)
            reason = safety(_densify(aimed)) if safety is not None else None
            if not reason:
                break
        if reason:
            log.warning("aim: %s at %s collides (%s); keeping the library motion",
                        gesture, target_name, reason)
        report = AimReport(gesture, target_name, ("left", "right")[wanted], mirrored, max(errors), converged,
                           applied=not reason, reason=reason or "")
        return aimed, report

    def _solve(self, keyframes: np.ndarray, side: int, target: np.ndarray, limits, abduction: float):
        lower, upper = limits.target_bounds(self.margin)
        roll = side * ARM_DOF + 1  # shoulder roll: + moves the left arm out, - the right
        aimed, errors, converged = keyframes.copy(), [], True
        for k in peak_indices(aimed, side, self.peak_fraction):
            seed = aimed[k].copy()
            seed[roll] += abduction if side == 0 else -abduction
            result = aim_arm(seed, side, target, lower, upper, tolerance=math.radians(self.tolerance_deg))
            aimed[k] = result.q
            errors.append(math.degrees(result.error_rad))
            converged &= result.converged
        return aimed, errors, converged
