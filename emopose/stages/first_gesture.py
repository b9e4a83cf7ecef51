"""The first gesture fits: a reply's first gesture that cannot meet its word is played softer.

A reply's first gesture often sits on its first word, where its preparation has only the speech
pre-roll (`max_preroll_s`, 0.4 s) before it. The timeline already compresses it to `scale[0]` and goes
straight to the stroke start; what is left is bound by the joint speed bound, so more time scaling cannot
help. Policy (pipeline.stages.schedule.first_word), which keeps both the pre-roll and the speed bound:
when the timeline plans the earliest gesture "late", it is tried at each lower intensity in turn, down to
`lowest_intensity`: its interior keyframes pulled toward its start pose by gains[lower] / gains[requested]
(Eq. intensity's gains, shared with the modulate stage; a point between two poses inside the limits stays
inside them, and an aimed pose keeps its direction). A smaller excursion from rest is a shorter
preparation under the speed bound. The first intensity whose stroke arrives on time replaces the gesture:
its timing's fit is "softened" and its record carries the intensity played, so the schedule, the
recording and the web UI show what was chosen. If none fits, the requested gesture is kept and lands late.
A first gesture that starts away from rest (after the thinking gesture) is planned from the arm's pose
by the timeline itself (`arm`), so this policy sees its true preparation.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from emopose.stages.modulate import INTENSITY_GAINS, scale_excursion
from emopose.turn.model import GestureTiming, ModulatedGesture
from emopose.turn.timeline import TimelinePlanner


@dataclass(frozen=True)
class FirstWordSettings:
    lowest_intensity: int = 1  # the softest a late first gesture may be played; 5 (or above) = off
    # The YAML takes the modulate stage's; None (no modulate node: an ablated pipeline, which the order
    # check then refuses with its own message) means modulate's default gains.
    gains: tuple[float, ...] | None = INTENSITY_GAINS

    def __post_init__(self) -> None:
        if self.gains is None:
            object.__setattr__(self, "gains", INTENSITY_GAINS)
        if len(self.gains) != 5 or min(self.gains) <= 0:
            raise ValueError(f"first_word.gains needs 5 positive values, got {self.gains}")


def softened(gesture: ModulatedGesture, intensity: int, gains: tuple[float, ...]) -> ModulatedGesture:
    """`gesture` at a lower `intensity`: interior keyframes pulled toward the start pose."""
    q = scale_excursion(gesture.keyframes, gains[intensity - 1] / gains[gesture.intensity - 1])
    record = gesture.resolved.record.model_copy(update={"intensity": intensity})
    return replace(gesture, resolved=replace(gesture.resolved, record=record), keyframes=q)


def plan_fitting_first(planner: TimelinePlanner, gestures: list[ModulatedGesture], onsets: list[float],
                       arm: np.ndarray | None, settings: FirstWordSettings
                       ) -> tuple[list[ModulatedGesture], list[GestureTiming | str], float]:
    """The gestures as played (the first perhaps softened), their timings (or drop reasons), the pre-roll."""
    placed, preroll = planner.plan(gestures, onsets, arm)
    if not gestures:
        return gestures, placed, preroll
    first = min(range(len(gestures)), key=lambda k: onsets[k])
    timing = placed[first]
    if isinstance(timing, str) or timing.fit != "late":
        return gestures, placed, preroll
    for intensity in range(gestures[first].intensity - 1, settings.lowest_intensity - 1, -1):
        trial = list(gestures)
        trial[first] = softened(gestures[first], intensity, settings.gains)
        out, trial_preroll = planner.plan(trial, onsets, arm)
        fitted = out[first]
        if not isinstance(fitted, str) and fitted.fit != "late":
            out[first] = replace(fitted, fit="softened")
            return trial, out, trial_preroll
    return gestures, placed, preroll
