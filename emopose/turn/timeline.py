"""Stroke-synchronous timeline: plan a whole reply's gestures so each stroke lands on its word.

BML-style sync points: every motion declares its stroke (keyframe indices, `LibraryEntry.stroke_span`).
A gesture's stroke start must *arrive* (the arm within `tolerance` rad of the stroke-start keyframe,
which is how it is measured) at its trigger word's onset + `lead_s`; the preparation is planned
backwards from there. Gestures are placed in the order of their words, each against the one before:

1. nominal: prepared from rest at its own speed after the previous gesture has fully retracted;
2. co-articulated: the previous gesture is cut at its stroke end and its last stroke pose blends
   (the paper's cubic blend) straight into this gesture's preparation, time-scaled within `scale`
   (slower first, holding the previous stroke pose for any time left), never beyond the speed bound;
3. shortened: as 2, cutting the previous stroke at an earlier keyframe (down to its stroke start); a
   blend the robot's safety check would refuse (the arms would collide) is not used;
4. retracted fast: the previous gesture retracts at up to `scale[0]`, this one prepares from rest;
5. via a pose, only where 2-3 fit in time but every blend was unsafe: the previous stroke (cut as in 3)
   blends to a via pose, halfway to rest ("via_halfway"), rest itself ("via_rest") or its own pose with
   both shoulders rolled outward ("via_apart": between two hands-together poses, such as hands_clasped
   then hands_on_heart, the other paths pass the hands through each other), and on into this
   preparation, the whole path passing the same safety check;
6. dropped, with the reason, when none of these fits.
Every placement passes the robot's safety check over its whole motion (emopose/turn/placement.py); a
refused timing is passed over for the next, and a gesture refused at every timing that fits is dropped
with the reason, so the schedule's softening tries it softer (emopose/stages/softening.py).
The first gesture may start before the speech: audio is delayed by up to `max_preroll_s`; if its
preparation needs more, it is compressed (down to `first_scale`: only the speed bound limits it), then
goes straight to the stroke start ("direct", after several preparation keyframes), then lands late.
Its first segment starts from wherever the arm is at its start time; when the arm is away from rest at
planning time (interrupted motion, the thinking gesture), that segment is long enough from there too.
`lag_s` moves everything earlier for the actuators' tracking lag. Segments keep a motion's `times:`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from emopose import STROKE_TOLERANCE
from emopose.execution.trajectory import TrajectoryBuilder, blend_weight, smoothstep
from emopose.robot.kinematics import arms_apart
from emopose.turn.model import Fit, GestureTiming, ModulatedGesture
from emopose.turn.placement import PathCheck, Placed

_U = np.linspace(0.0, 1.0, 201)
# Outward shoulder roll of the "via_apart" pose: parts the fingertips of clasped hands by 8-13 cm each side,
# which the hands_clasped -> hands_on_heart blend needs (0.2 rad left it refused).
VIA_APART_ROLL = 0.35
_BLEND_CURVE = blend_weight(_U)


@dataclass(frozen=True)
class TimelineSettings:
    lead_s: float = -0.05
    scale: tuple[float, float] = (0.6, 1.3)
    max_preroll_s: float = 0.4
    first_scale: float = 0.4  # the most a reply's first preparation is compressed (<= scale[0])
    tolerance: float = STROKE_TOLERANCE
    lag_s: float = 0.0

    def __post_init__(self) -> None:
        low, high = self.scale
        if not 0 < low <= 1.0 <= high:
            raise ValueError(f"timeline scale bounds must satisfy 0 < low <= 1 <= high, got {self.scale}")
        if not 0 < self.first_scale <= low:
            raise ValueError(f"timeline first_scale must be in (0, scale[0]], got {self.first_scale}")
        if self.max_preroll_s < 0 or self.tolerance <= 0:
            raise ValueError("timeline max_preroll_s must be >= 0 and tolerance > 0")


class TimelinePlanner:
    def __init__(self, builder: TrajectoryBuilder, settings: TimelineSettings,
                 safety: Callable[[np.ndarray], str | None] | None = None) -> None:
        self.builder = builder
        self.settings = settings
        self.check = PathCheck(builder, safety)  # the sequencer's pre-dispatch check, on every placement
        knots = np.arange(builder.increments + 1) / builder.increments
        self._smooth_curve = np.interp(_U, knots, smoothstep(knots))  # the waypoint easing G samples

    def plan(self, gestures: list[ModulatedGesture], onsets: list[float],
             arm: np.ndarray | None = None) -> tuple[list[GestureTiming | str], float]:
        """Timing (or a drop reason) per gesture, in the given order, and the speech pre-roll (s).
        `arm`: the arm's pose now, if it may not be at rest when the first gesture starts."""
        out: list[GestureTiming | str] = [""] * len(gestures)
        placed: list[tuple[int, Placed]] = []
        for k in sorted(range(len(gestures)), key=lambda k: onsets[k]):
            aim = onsets[k] + self.settings.lead_s - self.settings.lag_s
            gesture = self._place(gestures[k], aim, placed[-1][1] if placed else None, arm)
            if isinstance(gesture, str):
                out[k] = gesture
            else:
                placed.append((k, gesture))
        for k, gesture in placed:
            out[k] = gesture.timing()
        preroll = max(0.0, -min((g.times[0] for _, g in placed), default=0.0))
        return out, preroll

    # -- placing one gesture -------------------------------------------------------------------------
    def _place(self, gesture: ModulatedGesture, aim: float, prev: Placed | None,
               arm: np.ndarray | None) -> Placed | str:
        anchors, stroke, steps = self._shape(gesture)
        low, high = self.settings.scale
        name = gesture.name
        if prev is None:
            # origins stacked (m, 14): segment bounds and approach distances take the farthest one; a
            # blend from `arm` back to rest stays between the two, so both bounds cover it
            origins = anchors[:1] if arm is None else np.vstack([anchors[0], arm])
            earliest = -self.settings.max_preroll_s
            placed = self._prepare(name, anchors, stroke, steps, origins, False, earliest, aim,
                                   (1.0, self.settings.first_scale))
            if isinstance(placed, Placed):
                return placed
            late = self._late(name, anchors, stroke, steps, origins, earliest, aim)
            unsafe = self.check.refusal(late, origins)
            return f"unsafe: the safety check refuses every timing that fits ({unsafe})" if unsafe else late
        placed = self._prepare(name, anchors, stroke, steps, anchors[0], False, prev.times[-1], aim,
                               (1.0, 1.0))
        if isinstance(placed, Placed):
            return placed
        itself = placed or ""  # refused even from rest, after prev has retracted: the motion, not a blend
        unsafe = itself
        for cut in range(prev.stroke[1], prev.stroke[0] - 1, -1):
            placed = self._prepare(name, anchors, stroke, steps, prev.anchors[cut], True, prev.times[cut],
                                   aim, (high, low))
            if isinstance(placed, Placed):
                prev.cut = cut
                placed.fit = "coarticulated" if cut == prev.stroke[1] else "shortened"
                return placed
            unsafe = placed or unsafe  # None: no time at this cut; cutting earlier leaves more
        retraction = self._retract(prev, low)
        placed = self._prepare(name, anchors, stroke, steps, anchors[0], False, retraction[-1], aim,
                               (1.0, low))
        if isinstance(placed, Placed):
            prev.times[prev.stroke[1]:] = retraction
            return placed
        via = self._via(name, anchors, stroke, steps, prev, aim) if unsafe else None
        if via is not None:
            return via
        if itself:
            return f"unsafe: the safety check refuses every timing that fits, even from rest ({itself})"
        room = aim - prev.times[prev.stroke[0]]
        why = f"blending from {prev.name} is unsafe ({unsafe}) and no safe via pose fits" if unsafe else (
            f"too little to prepare at {low:g}x and the joint speed bound")
        return f"no room: its stroke is {room * 1e3:.0f} ms after {prev.name}'s stroke start; {why}"

    def _via(self, name, anchors, stroke, steps, prev: Placed, aim: float) -> Placed | None:
        """Rule 5: the first safe path from prev's stroke (latest cut first) through a via pose."""
        low, high = self.settings.scale
        for cut in range(prev.stroke[1], prev.stroke[0] - 1, -1):
            start_pose = prev.anchors[cut]
            apart = self.builder.limits.keep_inside(arms_apart(start_pose, VIA_APART_ROLL))  # a target pose
            for via, fit in (((start_pose + anchors[0]) / 2, "via_halfway"), (anchors[0], "via_rest"),
                             (apart, "via_apart")):
                shape = np.vstack([anchors[:1], via, anchors[1:]])  # the via segment as long as the first
                placed = self._prepare(name, shape, (stroke[0] + 1, stroke[1] + 1), np.r_[steps[:1], steps],
                                       start_pose, True,
                                       prev.times[cut], aim, (high, low), lead=2)
                if isinstance(placed, Placed):
                    prev.cut, placed.fit = cut, fit
                    return placed
        return None

    def _retract(self, prev: Placed, scale: float) -> list[float]:
        """prev's keyframe times from its stroke end on, with the retraction time-scaled."""
        end = prev.stroke[1]
        durations = self._durations(prev.anchors, prev.anchors[0], end, len(prev.anchors) - 1,
                                    prev.steps * scale, False)
        return np.cumsum([prev.times[end], *durations]).tolist()

    @staticmethod
    def _shape(gesture: ModulatedGesture) -> tuple[np.ndarray, tuple[int, int], np.ndarray]:
        """Anchors (a pose becomes start -> pose), stroke indices and the nominal segment lengths: the
        entry's own keyframe times where it gives them (`times:`, scaled to the duration), else even."""
        q, entry, d = np.asarray(gesture.keyframes, dtype=float), gesture.resolved.entry, gesture.duration
        if len(q) == 1:
            return np.vstack([q, q]), (1, 1), np.array([d])
        steps = np.full(len(q) - 1, d / (len(q) - 1)) if entry.times is None else np.diff(entry.times) * (
            d / entry.times[-1])
        return q, entry.stroke_span, steps

    def _prepare(self, name, anchors, stroke, steps, start_pose, blend_in, earliest, aim,
                 scales, lead: int = 1) -> Placed | str | None:
        """Latest start >= earliest whose stroke arrives at `aim`, trying time scales from scales[0] down
        to scales[1], then (a stroke after several preparation keyframes) going straight to the stroke
        start from the first `lead` anchors, passing over any the safety check refuses; None if even the
        last would need to start before `earliest`, the first refusal's reason if every one that fits was
        refused."""
        refused, tried = "", set()  # scales the speed bound clamps give the same timing: check it once
        shapes = [(anchors, stroke, steps, None)]
        if stroke[0] > lead:  # skip the intermediate preparation keyframes (and their segments' time)
            shapes.append((np.vstack([anchors[:lead], anchors[stroke[0]:]]),
                           (lead, stroke[1] - stroke[0] + lead),
                           np.r_[steps[:lead - 1], steps[stroke[0] - 1:]], "direct"))
        grid = np.arange(scales[0], scales[1] - 1e-9, -0.05).tolist() + [scales[1]]
        for shape, sync, shape_steps, how in shapes:
            for scale in np.unique(np.clip(grid, scales[1], scales[0]))[::-1]:
                durations = self._durations(shape, start_pose, 0, sync[0], shape_steps * scale, blend_in)
                arrival_lead = self._approach(start_pose if sync[0] == 1 else shape[sync[0] - 1],
                                              shape[sync[0]], durations[-1], blend_in and sync[0] == 1)
                start = aim + arrival_lead - sum(durations)
                if start >= earliest - 1e-9:
                    fit: Fit = how or ("nominal" if scale == 1.0 else "scaled")
                    placed = self._finish(name, shape, sync, shape_steps, start_pose, start, durations, aim,
                                          aim, fit, blend_in, float(scale))
                    if tuple(placed.times) in tried:
                        continue
                    tried.add(tuple(placed.times))
                    unsafe = self.check.refusal(placed, start_pose)
                    if not unsafe:
                        return placed
                    refused = refused or unsafe
        return refused or None

    def _late(self, name, anchors, stroke, steps, origins, start, aim) -> Placed:
        """The first gesture when even the pre-roll and the fastest preparation cannot meet its word."""
        low = self.settings.first_scale
        durations = self._durations(anchors, origins, 0, stroke[0], steps * low, False)
        before = origins if stroke[0] == 1 else anchors[stroke[0] - 1]
        arrival = start + sum(durations) - self._approach(before, anchors[stroke[0]], durations[-1], False)
        return self._finish(name, anchors, stroke, steps, origins, start, durations, aim, arrival, "late",
                            False, low)

    def _finish(self, name, anchors, stroke, steps, start_pose, start, prep, aim, arrival, fit, blend_in,
                scale) -> Placed:
        rest = self._durations(anchors, start_pose, stroke[0], len(anchors) - 1, steps, False)
        times = np.cumsum([start, *prep, *rest]).tolist()
        return Placed(name, anchors, stroke, steps, times, aim, arrival, fit, blend_in, scale)

    def _durations(self, anchors, start_pose, first, last, lengths, blend_in) -> list[float]:
        """Each segment from keyframe `first` to `last`: lengths[i - 1] into keyframe i, or its minimum."""
        out = []
        for i in range(first + 1, last + 1):
            origin = start_pose if i == 1 else anchors[i - 1]
            shortest = self.builder.segment_minimum(origin, anchors[i], blend_in and i == 1)
            out.append(max(float(lengths[i - 1]), shortest, self.builder.dt))
        return out

    def _approach(self, q_from: np.ndarray, q_to: np.ndarray, duration: float, blend: bool) -> float:
        """How long before the end of a segment the arm comes within the tolerance of its target."""
        distance = float(np.max(np.abs(q_to - q_from)))
        if distance <= self.settings.tolerance:
            return duration
        curve = _BLEND_CURVE if blend else self._smooth_curve
        u = float(np.interp(1.0 - self.settings.tolerance / distance, curve, _U))
        return duration * (1.0 - u)
