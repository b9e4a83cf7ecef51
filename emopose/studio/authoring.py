"""Pose Studio's view of a draft motion: the trajectory the robot would run, and the checks before saving.

The preview runs the execution code itself: Eq. intensity (the Modulate stage with the pipeline's
gains and margin), Eq. smoothstep (TrajectoryBuilder.build) from the neutral rest pose, and the
sequencer's own safety hook; so what Pose Studio shows is what the sequencer would accept or reject.
Every intensity level is checked, and a motion that self-collides at any of them cannot be saved: the
planner may ask for any level, and the sequencer would reject the gesture at run time (blocking the save
is simpler and more honest than storing a per-intensity ceiling that every caller must respect).
Where the arm stands when the motion starts matters too. Rest (a session's start on the simulator, every
gesture after a retraction) blocks the save like the levels; each distinct end pose of a library motion
(itself included) at any level, where the arm holds after a gesture not followed by rest, is checked and
reported as a warning. Not checked (said in `DraftReport.checked`): co-articulated starts, whose blends
the timeline checks and replaces by a retraction when unsafe, and a real robot's pose at connect.
"""

from __future__ import annotations

import re
import time
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
class StartCheck:
    """The draft at every level from one pose the arm can be in when it starts."""

    start: str  # "rest (neutral_rest)", "the end pose of neutral_ready at intensity 3"...
    failed_levels: list[int]
    reason: str | None  # the first failure's


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
    timing_faults: list[str]  # authored keyframe times the joint speed bound forbids: saving refuses them
    levels: list[LevelCheck]  # from rest
    starts: list[StartCheck]  # from the other poses the arm can start in (rest excluded)
    check_s: float  # what checking every start pose at every level took

    @property
    def checked(self) -> str:
        """Plainly, which starts the self-collision check covered (and which it did not)."""
        return (f"intensities {LEVELS[0]}-{LEVELS[-1]} from rest and from {len(self.starts)} other start "
                f"pose(s): the end poses of library motions (this one included); not from co-articulated "
                f"starts (the timeline checks those blends live) nor a real robot's pose at connect")

    @property
    def problems(self) -> list[str]:
        """What blocks saving."""
        out = [self._outside_limits] if self.keyframe_violations else []
        out += [f"keyframe times too fast for the joint speed bound: {fault}" for fault in self.timing_faults]
        out += [f"self-collision at intensity {c.intensity} (the sequencer would reject it): {c.reason}"
                for c in self.levels if not c.ok]
        return out

    @property
    def warnings(self) -> list[str]:
        """Starts other than rest it collides from: shown, not blocking (shipped motions have such starts;
        live, the sequencer rejects the gesture there and the reply goes on without it)."""
        return [f"self-collision at intensity {', '.join(map(str, c.failed_levels))} when it starts from "
                f"{c.start} (the sequencer would reject it there): {c.reason}"
                for c in self.starts if c.failed_levels]

    def refusal_at(self, intensity: int) -> str | None:
        """Why the draft cannot be performed at this intensity (None: it can)."""
        level = next(c for c in self.levels if c.intensity == intensity)
        if self.keyframe_violations or self.timing_faults:
            return self.problems[0]
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
              stroke: tuple[int, int] | None = None, times: list[float] | None = None) -> LibraryEntry:
        """Schema-check the keyframes, stroke and keyframe times (not the limits nor the speed bound: those
        are reported, so the author can fix them)."""
        raw = {"name": DRAFT_NAME, "class": cls, "description": "Pose Studio draft",
               "motion_type": motion_type, "duration": duration, "keyframes": keyframes, "stroke": stroke,
               "times": times}
        try:
            return LibraryEntry.model_validate(raw)
        except ValidationError as exc:
            problems = "; ".join(f"{'.'.join(map(str, e['loc'])) or 'draft'}: {e['msg']}"
                                 for e in exc.errors())
            raise DraftError(problems) from exc

    def report(self, entry: LibraryEntry, intensity: int = NOMINAL_LEVEL) -> DraftReport:
        started = time.perf_counter()
        start = self.library.neutral_entry.q[0]
        levels, chosen = [], None
        for level in LEVELS:
            q = self.modulate.keyframes(entry.q, level)
            trajectory = self.builder.build(q, entry.default_duration, start, entry.times)
            levels.append(self._check(level, trajectory))
            if level == intensity:
                chosen = (q, trajectory)
        starts = [self._check_from(entry, label, pose) for label, pose in self.start_poses(entry)[1:]]
        keyframes, trajectory = chosen
        limits = self.library.limits
        # Eq. duration, shown beside
        rule = entry.model_copy(update={"duration": None, "times": None}).default_duration
        return DraftReport(
            intensity=intensity, duration=entry.default_duration, default_duration=rule,
            explicit_duration=entry.duration is not None, keyframes=keyframes, trajectory=trajectory,
            keyframe_violations=limits.violations(entry.q, self.library.limit_margin),
            trajectory_violations=limits.violations(trajectory.samples),
            timing_faults=self.builder.timing_faults(entry.q, entry.times) if entry.times else [],
            levels=levels, starts=starts,
            check_s=time.perf_counter() - started)

    def start_poses(self, entry: LibraryEntry) -> list[tuple[str, np.ndarray]]:
        """Rest first, then each distinct end pose of the library's motions (entry's replacing its saved
        namesake) at every level: where the arm can stand when `entry` starts."""
        rest = self.library.neutral_entry.q[0]
        poses = [(f"rest ({self.library.snapshot.neutral})", rest)]
        others = [e for e in self.library.snapshot.entries.values() if e.name != entry.name]
        for other in [*others, entry]:
            for level in LEVELS:
                end = self.modulate.keyframes(other.q, level)[-1]
                if not any(np.allclose(end, q, atol=1e-6) for _, q in poses):
                    name = "itself" if other is entry else other.name
                    poses.append((f"the end pose of {name} at intensity {level}", end))
        return poses

    def _check_from(self, entry: LibraryEntry, label: str, start: np.ndarray) -> StartCheck:
        failed, first = [], None
        for level in LEVELS:
            trajectory = self.builder.build(self.modulate.keyframes(entry.q, level), entry.default_duration,
                                            start, entry.times)
            reason = self._refusal(trajectory)
            if reason is not None:
                failed.append(level)
                first = first or reason
        return StartCheck(label, failed, first)

    def _check(self, level: int, trajectory: Trajectory) -> LevelCheck:
        collision = self.checker.check(trajectory.samples)
        reason = self._refusal(trajectory, collision.reason)
        return LevelCheck(level, reason is None, reason, float(collision.min_clearance_m),
                          float(trajectory.stretch))

    def _refusal(self, trajectory: Trajectory, checked: str | None = "unchecked") -> str | None:
        """The sequencer's hook is the authority (it carries the configured clearance); without one
        (safety=off) the default checker still informs the author (`checked`: its verdict, if known).
        The reason names a time and keyframes, not a sample index."""
        samples = trajectory.samples
        if self.safety is not None:
            reason = self.safety(samples)
        else:
            reason = self.checker.check(samples).reason if checked == "unchecked" else checked
        return None if reason is None else cite_time(reason, trajectory)


def cite_time(reason: str, trajectory: Trajectory) -> str:
    """'... at sample 22: ...' as '... at 0.44 s (between K1 and K2): ...': what the author can find on
    the timeline. Anchor 0 is the start pose (in a sequence it takes keyframe 0's place, so anchor i is
    keyframe i); a pose has two anchors, the start and its one keyframe K0."""
    ticks = trajectory.anchor_ticks
    names = ["the start", "K0"] if len(ticks) == 2 else [f"K{i}" for i in range(len(ticks))]

    def where(match: re.Match) -> str:
        n = int(match.group(1))
        at = f"at {n * trajectory.dt:.2f} s"
        if not ticks:
            return at
        i = max(k for k, tick in enumerate(ticks) if tick <= n)
        if n == ticks[i]:
            return f"{at} (at {names[i]})"
        if i + 1 < len(ticks):
            return f"{at} (between {names[i]} and {names[i + 1]})"
        return f"{at} (after {names[i]})"

    return re.sub(r"at sample (\d+)", where, reason)
