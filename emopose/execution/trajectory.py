"""Trajectory construction G (Eq. smoothstep) and the cubic blend (Eq. blend).

G: the keyframe path q_last -> q~_1 -> ... -> q~_{K-1} (the first segment starts at the latest
published pose in place of q~_0, so the initial transition is embedded and the duration stays d) is
cut into M = 5 smoothstep increments per segment, w_{k,r} = q_{k-1} + s(r/M)(q_k - q_{k-1}) with
s(u) = 3u^2 - 2u^3, then linearly resampled at 50 Hz and projected into the hard limits.
A pose (one keyframe) is a single segment from q_last to the pose. A library entry may state when each
keyframe is reached (`times`); the segments then follow those times, with the same easing.

Beyond the paper: commands are planned inside the limits file's tracking reserve (JointLimits.planning: a
share of max_velocity, a margin inside the hard limits), so the measured arm, which overshoots its commands,
stays inside the bounds themselves. If a sample step would exceed that speed bound (for example an
intensity-5 excursion, or a start far from the first keyframe), the whole trajectory is slowed down
uniformly until it does not; `stretch` reports the factor. Blends get the same treatment.

Timed construction (the timeline): each keyframe has its own time, so segments differ in length; a
segment too short for the speed bound is lengthened and everything after it moves later (`late_s`).
The first segment of a co-articulated gesture eases with the cubic blend beta instead of the smoothstep.

Catching up (beyond the paper): a motion left behind by a stall (the loop did not tick) is rebuilt from
where the arm stands to the keyframes it has not reached, each on the tick it was built for, lengthening
only what the speed bound forbids; so a stroke still lands on its time when the bound allows. The arm
stands on its way to the next keyframe, so the joint-space path stays the one the safety check passed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from emopose import CONTROL_DT
from emopose.joint_limits import JointLimits
from emopose.sync.strokes import first_within

SMOOTHSTEP_INCREMENTS = 5


def smoothstep(u: np.ndarray | float) -> np.ndarray | float:
    return 3 * u**2 - 2 * u**3


def blend_weight(u: np.ndarray) -> np.ndarray:
    """beta(u) of Eq. blend: 4u^3 for u < 1/2, else 1 - (-2u + 2)^3 / 2."""
    return np.where(u < 0.5, 4 * u**3, 1 - 0.5 * (2 - 2 * u) ** 3)


@dataclass(frozen=True)
class Trajectory:
    """(N + 1, 14) samples at t = n * dt; samples[0] is the pose it starts from, samples[-1] its end."""

    samples: np.ndarray
    dt: float
    stretch: float = 1.0
    anchor_ticks: tuple[int, ...] = ()  # sample index at which each keyframe is reached (0: the start pose)
    late_s: float = 0.0  # timed builds: how much later than asked the last keyframe is reached
    anchors: np.ndarray | None = None  # the poses the anchor ticks reach (anchors[0]: the start pose)

    @property
    def duration(self) -> float:
        return (len(self.samples) - 1) * self.dt

    def arrival_tick(self, keyframes: np.ndarray, key: int) -> int:
        """The sample at which the arm comes within STROKE_TOLERANCE of keyframes[key] on its way there
        (the stroke's arrival), at the latest the sample that reaches it."""
        reached = self.anchor_ticks[max(key, 1)]
        hit = first_within(self.samples[1:reached + 1], np.asarray(keyframes)[key])
        return reached if hit is None else 1 + hit


class TrajectoryBuilder:
    """Builds G(entry keyframes, intensity-modulated, q_last) and blends, within limits and speed bounds
    less the limits file's tracking reserve."""

    def __init__(self, limits: JointLimits, dt: float = CONTROL_DT, increments: int = SMOOTHSTEP_INCREMENTS):
        self.limits = limits.planning()  # the hard limits and speed bounds less the tracking reserve
        self.dt = dt
        self.increments = increments
        self._s = smoothstep(np.arange(1, increments + 1) / increments)[None, :, None]
        # Largest waypoint step as a fraction of its segment (the middle increment of the smoothstep).
        self._steepest = float(np.max(np.diff(smoothstep(np.arange(increments + 1) / increments))))
        self._weights_cache: dict[tuple[int, float], np.ndarray] = {}
        self._inv_velocity = 1.0 / self.limits.max_velocity

    def waypoints(self, keyframes: np.ndarray, q_last: np.ndarray) -> np.ndarray:
        """Eq. smoothstep waypoints, (segments * M + 1, 14), starting at q_last."""
        anchors = np.array(keyframes, dtype=float, ndmin=2)
        anchors = np.vstack([q_last, anchors]) if len(anchors) == 1 else np.vstack([q_last, anchors[1:]])
        start, delta = anchors[:-1, None, :], np.diff(anchors, axis=0)[:, None, :]
        inner = (start + self._s * delta).reshape(-1, anchors.shape[1])
        return np.vstack([q_last, inner])

    def resample(self, waypoints: np.ndarray, duration: float) -> np.ndarray:
        """Linear resampling of uniformly timed waypoints at dt; the last sample is the last waypoint."""
        n = max(1, math.ceil(duration / self.dt - 1e-9))
        x = np.minimum(np.arange(n + 1) * self.dt, duration) * ((len(waypoints) - 1) / duration)
        i0 = np.minimum(x.astype(int), len(waypoints) - 2)
        frac = (x - i0)[:, None]
        return waypoints[i0] + frac * (waypoints[i0 + 1] - waypoints[i0])

    def build(self, keyframes: np.ndarray, duration: float, q_last: np.ndarray,
              times: tuple[float, ...] | None = None) -> Trajectory:
        """G from q_last through keyframes[1:] (a pose: to its keyframe) over `duration`, the keyframes evenly
        spaced; or, given `times` (a library entry's own, times[0] = 0, times[-1] the duration), each
        keyframe reached at its time."""
        if times is not None:
            return self._build_authored(keyframes, times, q_last)
        # Same result as resample(waypoints(...)) (to ~1e-14), built in few numpy calls: every sample is a
        # fixed linear mix of the anchors that depends only on (segments, duration), so that matrix is
        # cached and a build is one product. The speed check needs only the anchor steps, since the
        # steepest waypoint step of a segment is its delta times the largest smoothstep increment.
        q_last = np.asarray(q_last, dtype=float)
        keyframes = np.asarray(keyframes, dtype=float)
        if keyframes.ndim == 1:
            keyframes = keyframes[None]
        rest = keyframes if len(keyframes) == 1 else keyframes[1:]  # q_last takes the first keyframe's place
        anchors = np.empty((len(rest) + 1, q_last.shape[-1]))
        anchors[0], anchors[1:] = q_last, rest
        step = anchors[1:] - anchors[:-1]
        np.abs(step, out=step)
        step *= self._inv_velocity
        ratio = float(step.max()) * self._steepest * len(rest) * self.increments / duration
        stretch = ratio * 1.001 if ratio > 1.0 else 1.0
        samples = self._weights(len(rest), duration * stretch) @ anchors
        np.maximum(samples, self.limits.lower, out=samples)  # = limits.project, minus np.clip's overhead
        np.minimum(samples, self.limits.upper, out=samples)
        samples[0] = q_last
        total = duration * stretch
        ticks = tuple(self.tick(total * i / len(rest)) for i in range(len(rest) + 1))
        return Trajectory(samples, self.dt, stretch, ticks, anchors=anchors)

    def _build_authored(self, keyframes: np.ndarray, times: tuple[float, ...],
                        q_last: np.ndarray) -> Trajectory:
        """Keyframe k reached at times[k]; slowed down uniformly, as build() is, so that no segment breaks the
        speed bound (an intensity-5 excursion, a start away from keyframe 0): the rhythm is kept."""
        anchors = np.vstack([q_last, np.asarray(keyframes, dtype=float)[1:]])
        gaps = np.diff(times)
        ratio = max(self.segment_minimum(a, b) / gap for a, b, gap in zip(anchors[:-1], anchors[1:], gaps))
        stretch = ratio * 1.001 if ratio > 1.0 else 1.0
        return replace(self.build_timed(anchors, np.asarray(times[1:]) * stretch, q_last), stretch=stretch)

    def timing_faults(self, keyframes: np.ndarray, times: tuple[float, ...]) -> list[str]:
        """Authored keyframe times the speed bound forbids, keyframes as written: one line per segment naming
        the keyframe, its time, the fastest joint and the shortest time the bound allows, rounded up to
        10 ms (0.302 s shows as 0.31 s: a gap of the time shown is then allowed)."""
        q, out = np.asarray(keyframes, dtype=float), []
        for k in range(1, len(q)):
            gap, needed = times[k] - times[k - 1], self.segment_minimum(q[k - 1], q[k])
            if needed > gap + 1e-9:
                j = int(np.argmax(np.abs(q[k] - q[k - 1]) * self._inv_velocity))
                shown = math.ceil(needed * 100 - 1e-9) / 100
                out.append(f"K{k} at {times[k]:.2f} s comes {gap:.2f} s after K{k - 1}; "
                           f"{self.limits.names[j]} needs {shown:.2f} s for it "
                           f"at its planning speed ({self.limits.max_velocity[j]:.2f} rad/s)")
        return out

    def tick(self, t: float) -> int:
        """The first sample index at or after time t."""
        return max(0, math.ceil(t / self.dt - 1e-9))

    def segment_minimum(self, q_from: np.ndarray, q_to: np.ndarray, blend: bool = False) -> float:
        """Shortest duration (s) of one eased segment that keeps every joint within its speed bound."""
        # beta' peaks at 3, the smoothstep waypoints' slope at ~1.48
        peak = 3.0 if blend else self._steepest * self.increments
        return peak * float(np.max(np.abs(np.asarray(q_to) - np.asarray(q_from)) * self._inv_velocity))

    def build_timed(self, keyframes: np.ndarray, times: np.ndarray, q_last: np.ndarray,
                    blend_in: bool = False) -> Trajectory:
        """Keyframes 1..n reached at `times` (s after the start, increasing); keyframe 0 is replaced by
        q_last. Segments the speed bound forbids are lengthened, delaying the rest."""
        anchors = np.array(keyframes, dtype=float, ndmin=2)
        anchors[0] = q_last
        wanted = np.asarray(times, dtype=float)
        ends, t = np.empty(len(anchors) - 1), 0.0
        for i in range(len(ends)):
            shortest = max(self.segment_minimum(anchors[i], anchors[i + 1], blend_in and i == 0), self.dt)
            t = max(wanted[i], t + shortest)
            ends[i] = t
        starts = np.concatenate([[0.0], ends[:-1]])
        grid = np.arange(self.tick(ends[-1]) + 1) * self.dt
        seg = np.minimum(np.searchsorted(ends, grid - 1e-12), len(ends) - 1)
        u = np.clip((grid - starts[seg]) / (ends[seg] - starts[seg]), 0.0, 1.0)
        knots = np.arange(self.increments + 1) / self.increments
        weight = np.interp(u, knots, smoothstep(knots))
        if blend_in:
            first = seg == 0
            weight[first] = blend_weight(u[first])
        samples = anchors[seg] + weight[:, None] * (anchors[seg + 1] - anchors[seg])
        samples = self.limits.project(samples)
        samples[0] = q_last
        ticks = (0, *(self.tick(e) for e in ends))
        return Trajectory(samples, self.dt, 1.0, ticks, float(ends[-1] - wanted[-1]), anchors)

    def catch_up(self, motion: Trajectory, index: int, resume: int) -> Trajectory:
        """The rest of `motion` after a stall: the arm stands at samples[index] and the returned motion's
        samples[0] is that pose at old tick `resume` (> index). The keyframes not yet reached keep their old
        ticks where the speed bound allows, else come as early as it allows; the anchor numbering is kept
        (reached keyframes get tick 0), so arrival_tick takes the same keyframe indices."""
        ahead = next(k for k, tick in enumerate(motion.anchor_ticks) if tick > index)
        here = motion.samples[index]
        wanted = (np.asarray(motion.anchor_ticks[ahead:]) - resume) * self.dt
        rest = self.build_timed(np.vstack([here, motion.anchors[ahead:]]), wanted, here)
        ticks = (0,) * ahead + rest.anchor_ticks[1:]
        return Trajectory(rest.samples, self.dt, motion.stretch, ticks, motion.late_s + rest.late_s,
                          motion.anchors)

    def _weights(self, segments: int, duration: float) -> np.ndarray:
        """(N + 1, segments + 1) matrix taking the anchors to the 50 Hz samples, cached per (segments, d)."""
        key = (segments, duration)
        weights = self._weights_cache.get(key)
        if weights is None:
            if len(self._weights_cache) >= 512:  # stretched builds have one-off durations; stay bounded
                self._weights_cache.clear()
            unit = np.eye(segments + 1)
            weights = self.resample(self.waypoints(unit, unit[0]), duration)
            weights.setflags(write=False)
            self._weights_cache[key] = weights
        return weights

    def blend(self, q_from: np.ndarray, q_to: np.ndarray, duration: float) -> Trajectory:
        """Eq. blend from q_from to q_to; lengthened only if `duration` would break the speed bound."""
        q_from, q_to = np.asarray(q_from, dtype=float), np.asarray(q_to, dtype=float)
        # beta' peaks at 3 (u = 1/2), so the fastest joint moves 3 |dq| / T.
        needed = float(np.max(3 * np.abs(q_to - q_from) / self.limits.max_velocity))
        length = max(duration, needed, self.dt)
        n = max(1, math.ceil(length / self.dt - 1e-9))
        u = np.arange(n + 1) / n
        samples = self.limits.project(q_from + blend_weight(u)[:, None] * (q_to - q_from))
        samples[0] = q_from
        return Trajectory(samples, self.dt, length / duration if duration > 0 else 1.0)
