"""Pose Studio's view of a draft motion: the trajectory the robot would run, and the checks before saving.

The preview runs the execution code itself: Eq. intensity (the Modulate stage with the pipeline's
gains and margin), Eq. smoothstep (TrajectoryBuilder.build) from the neutral rest pose, and the
sequencer's own safety hook; so what Pose Studio shows is what the sequencer would accept or reject.
Every intensity level is checked, and a motion that self-collides at any of them cannot be saved: the
planner may ask for any level, and the sequencer would reject the gesture at run time (blocking the save
is simpler and more honest than storing a per-intensity ceiling that every caller must respect).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from pydantic import ValidationError

from emopose.contract import LibraryEntry
from emopose.execution.trajectory import Trajectory, TrajectoryBuilder
from emopose.library import MotionLibrary
from emopose.robot.collision import SelfCollisionChecker
from emopose.stages.modulate import Modulate

LEVELS = (1, 2, 3, 4, 5)
NOMINAL_LEVEL = 3  # the library sequence as authored: the preview's default level
DRAFT_NAME = "studio_draft"  # what an unsaved draft is called when it runs (the sequencer's events name it)


class DraftError(ValueError):
    """The draft cannot be built (wrong shape, keyframe count...); the message says what to change."""


@dataclass(frozen=True)
class LevelCheck:
    intensity: int
    ok: bool
    reason: str | None
    min_clearance_m: float
    stretch: float


@dataclass(frozen=True)
class DraftReport:
    intensity: int
    duration: float
    default_duration: float
    explicit_duration: bool
    keyframes: np.ndarray  # (K, 14) after Eq. intensity
    trajectory: Trajectory  # (N + 1, 14) at 50 Hz from the neutral pose
    # joints outside the library's limits (+ margin): the library refuses these
    keyframe_violations: list[str]
    trajectory_violations: list[str]
    levels: list[LevelCheck]

    @property
    def problems(self) -> list[str]:
        """What blocks saving."""
        out = [self._outside_limits] if self.keyframe_violations else []
        out += [f"self-collision at intensity {c.intensity} (the sequencer would reject it): {c.reason}"
                for c in self.levels if not c.ok]
        return out

    def refusal_at(self, intensity: int) -> str | None:
        """Why the draft cannot be performed at this intensity (None: it can)."""
        level = next(c for c in self.levels if c.intensity == intensity)
        if self.keyframe_violations:
            return self._outside_limits
        return None if level.ok else f"self-collision at intensity {intensity}: {level.reason}"

    @property
    def _outside_limits(self) -> str:
        return f"keyframes leave the joint limits for {', '.join(self.keyframe_violations)}"


class PoseStudio:
    def __init__(self, library: MotionLibrary, modulate: Modulate | None = None,
                 safety: Callable[[np.ndarray], str | None] | None = None,
                 checker: SelfCollisionChecker | None = None) -> None:
        """`modulate`: the running pipeline's stage (its gains and margin), else the paper's law;
        `safety`: the sequencer's hook, so a draft is judged as execution would judge it."""
        self.library, self.safety = library, safety
        self.modulate = modulate or Modulate(library.limits)
        self.checker = checker or SelfCollisionChecker()
        self.builder = TrajectoryBuilder(library.limits)

    def draft(self, keyframes: list[list[float]], motion_type: str = "sequence",
              duration: float | None = None, cls: str = "neutral",
              stroke: tuple[int, int] | None = None) -> LibraryEntry:
        """Schema-check the keyframes and stroke (not the limits: those are reported, so the author can
        fix them)."""
        raw = {"name": DRAFT_NAME, "class": cls, "description": "Pose Studio draft",
               "motion_type": motion_type, "duration": duration, "keyframes": keyframes, "stroke": stroke}
        try:
            return LibraryEntry.model_validate(raw)
        except ValidationError as exc:
            problems = "; ".join(f"{'.'.join(map(str, e['loc'])) or 'draft'}: {e['msg']}"
                                 for e in exc.errors())
            raise DraftError(problems) from exc

    def report(self, entry: LibraryEntry, intensity: int = NOMINAL_LEVEL) -> DraftReport:
        start = self.library.neutral_entry.q[0]
        levels, chosen = [], None
        for level in LEVELS:
            q = self.modulate.keyframes(entry.q, level)
            trajectory = self.builder.build(q, entry.default_duration, start)
            levels.append(self._check(level, trajectory))
            if level == intensity:
                chosen = (q, trajectory)
        keyframes, trajectory = chosen
        limits = self.library.limits
        rule = entry.model_copy(update={"duration": None}).default_duration  # Eq. duration, shown beside
        return DraftReport(
            intensity=intensity, duration=entry.default_duration, default_duration=rule,
            explicit_duration=entry.duration is not None, keyframes=keyframes, trajectory=trajectory,
            keyframe_violations=limits.violations(entry.q, self.library.limit_margin),
            trajectory_violations=limits.violations(trajectory.samples), levels=levels)

    def _check(self, level: int, trajectory: Trajectory) -> LevelCheck:
        collision = self.checker.check(trajectory.samples)
        # The sequencer's hook is the authority (it carries the configured clearance); without one
        # (safety=off) the default checker still informs the author.
        reason = self.safety(trajectory.samples) if self.safety is not None else collision.reason
        return LevelCheck(level, reason is None, reason, float(collision.min_clearance_m),
                          float(trajectory.stretch))
