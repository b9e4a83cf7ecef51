"""The posture layer: what the arms do between gestures, so the robot does not freeze at rest (beyond the
paper; NVIDIA ACE keeps a similar layer that gestures return to).

Three postures: `rest` (the library's neutral pose), `listening` (while the visitor speaks or types) and
`thinking` (while a reply is planned), 14-joint poses set in conf/posture/ and checked at least
POSE_MARGIN inside the joint limits. The sequencer steers to the current posture wherever it steered to
neutral (the recovery after a hold, an interrupt, a stalled gesture), blends to a new posture at the next
tick when nothing runs or waits, and ends each gesture in the posture: its retraction (the last keyframe)
moves by the posture's offset from rest. A gesture still prepares from the pose last published.
With `rest` and idle motion off the command stream is exactly the one without a posture layer.

Idle motion (`idle_motion`): while the sequencer is settled (nothing runs, nothing waits) a breathing-scale
oscillation is added to the held pose, two sines of at most `idle_amplitude` together (a few hundredths of
a radian) fading in from zero, far below the speed bounds. Its clock advances at most one control period
a tick, so a loop that was not ticked (a stall, an offline job between turns) resumes it where it stopped.
When anything starts, the pose published last becomes the pose the new motion starts from (folded in), so
the stream never steps.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from emopose.execution.gesture_command import GestureCommand
from emopose.joint_limits import JointLimits

REST, LISTENING, THINKING = "rest", "listening", "thinking"
POSE_MARGIN = 0.1  # rad inside the hard limits, as the library's keyframes keep (library/README.md)
MAX_IDLE_AMPLITUDE = 0.05  # rad: breathing scale; more would read as a gesture
SWAY_PERIODS = 2.7  # the slower sway's period, in breaths
# Per-joint shapes (14-joint order, right arm mirrored): a breath lifts the upper arms a little forward and
# out and flexes the elbows; a slower sway turns the forearms. Each joint's two weights sum to at most 1.
BREATH = np.array([-0.6, 0.4, 0.0, -0.7, 0.0, 0.3, 0.0, -0.6, -0.4, 0.0, -0.7, 0.0, 0.3, 0.0])
SWAY = np.array([0.0, 0.0, 0.4, 0.3, 0.3, 0.0, 0.2, 0.0, 0.0, -0.4, 0.3, -0.3, 0.0, -0.2])


@dataclass(frozen=True)
class PostureSettings:
    """conf/posture/: the listening and thinking poses (rest is the library's neutral pose), the blend time
    between postures (lengthened where the speed bound needs it) and the idle motion."""

    listening: tuple[float, ...]
    thinking: tuple[float, ...]
    transition_s: float = 0.8
    idle_motion: bool = False  # on in serve and tour_lab (conf/experiment/)
    idle_amplitude: float = 0.03  # rad, the largest joint's excursion
    breath_period_s: float = 5.0
    fade_in_s: float = 2.0

    def __post_init__(self) -> None:
        if not 0.0 <= self.idle_amplitude <= MAX_IDLE_AMPLITUDE:
            raise ValueError(f"posture.idle_amplitude={self.idle_amplitude}: must be 0..{MAX_IDLE_AMPLITUDE} "
                             "rad (breathing scale)")
        if self.breath_period_s < 2.0:
            raise ValueError(f"posture.breath_period_s={self.breath_period_s}: must be >= 2 s (slow)")
        if self.transition_s <= 0 or self.fade_in_s < 0:
            raise ValueError("posture.transition_s must be > 0 and posture.fade_in_s >= 0")


class PostureLayer:
    """The current posture, the one the stream heads for, and the idle motion. Without settings it stays at
    rest and still (a Sequencer built without a posture: the stream of before). `request` may be called
    from any thread; everything else runs under the sequencer's lock."""

    def __init__(self, settings: PostureSettings | None, rest: np.ndarray, limits: JointLimits,
                 dt: float) -> None:
        self.settings, self.limits, self.dt = settings, limits, dt
        self.rest = np.asarray(rest, dtype=float)
        self.poses = {REST: self.rest}
        if settings is not None:
            self.poses |= {LISTENING: self._checked(LISTENING, settings.listening),
                           THINKING: self._checked(THINKING, settings.thinking)}
        self.current = self.heading = REST  # the requested posture; the one the stream heads for
        self._anchor: np.ndarray | None = None  # the held pose the idle motion moves about, while it runs
        self._idle_t = 0.0  # the idle motion's clock
        self._last_now: float | None = None

    def _checked(self, name: str, values) -> np.ndarray:
        pose = np.asarray(values, dtype=float)
        if pose.shape != self.rest.shape or not np.all(np.isfinite(pose)):
            raise ValueError(f"posture.{name}: needs {len(self.rest)} finite joint angles (rad), "
                             f"got {values!r}")
        outside = self.limits.violations(pose, POSE_MARGIN)
        if outside:
            raise ValueError(f"posture.{name}: {', '.join(outside)} not {POSE_MARGIN} rad inside the joint "
                             "limits")
        return pose

    def request(self, name: str) -> None:
        """From now on the arms return to posture `name` (a disabled layer ignores it)."""
        if name not in (REST, LISTENING, THINKING):
            raise ValueError(f"unknown posture {name!r}: one of {REST}, {LISTENING}, {THINKING}")
        if self.settings is not None:
            self.current = name

    @contextmanager
    def holding(self, name: str) -> Iterator[None]:
        """Posture `name` for the block (a reply being planned: thinking), rest after it."""
        self.request(name)
        try:
            yield
        finally:
            self.request(REST)

    @property
    def stale(self) -> bool:
        """The posture changed since the stream last headed for one."""
        return self.current != self.heading

    def home(self) -> np.ndarray:
        """The current posture's pose; the stream heads there from now on."""
        self.heading = self.current
        return self.poses[self.current]

    def retarget(self, command: GestureCommand, home: np.ndarray) -> np.ndarray:
        """The command's keyframes ending in `home`: the retraction's end (last keyframe) moved by home's
        offset from rest. A command cut after its stroke, or a pose, is kept as it is."""
        keyframes = np.asarray(command.keyframes)
        offset = home - self.rest
        last = len(keyframes) - 1 if keyframes.ndim == 2 else 0
        ends_in_stroke = command.stroke is not None and command.stroke[1] >= last
        if command.cut or last < 1 or ends_in_stroke or not offset.any():
            return keyframes
        moved = keyframes.astype(float)
        moved[-1] += offset
        return moved

    def idle(self, last: np.ndarray, now: float, settled: bool) -> np.ndarray:
        """The pose to publish at `now` after `last`: moved by the idle motion while settled, else `last`."""
        advance = 0.0 if self._last_now is None else min(max(now - self._last_now, 0.0), self.dt)
        self._last_now = now
        if not (settled and self.settings is not None and self.settings.idle_motion):
            self._anchor = None
            return last
        if self._anchor is None:
            self._anchor, self._idle_t = last.copy(), 0.0
        else:
            self._idle_t += advance
        anchor = self._anchor
        q = anchor + self._offset(self._idle_t)
        return np.clip(q, np.minimum(anchor, self.limits.lower), np.maximum(anchor, self.limits.upper))

    def held(self, last: np.ndarray) -> np.ndarray:
        """The pose held, without the idle motion's excursion."""
        return last if self._anchor is None else self._anchor

    def _offset(self, t: float) -> np.ndarray:
        settings = self.settings
        u = 1.0 if settings.fade_in_s == 0 else min(t / settings.fade_in_s, 1.0)
        phase = 2 * math.pi * t / settings.breath_period_s
        wave = BREATH * math.sin(phase) + SWAY * math.sin(phase / SWAY_PERIODS)
        return settings.idle_amplitude * (3 * u**2 - 2 * u**3) * wave

    def reset(self) -> None:
        """A new stream: the idle motion starts afresh."""
        self._anchor, self._last_now = None, None
