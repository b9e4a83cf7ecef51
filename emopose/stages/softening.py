"""Softer when it does not fit: a gesture the timeline cannot place on its word is played less intensely.

A reply's first gesture often sits on its first word, where its preparation has only the speech pre-roll
(`max_preroll_s`, 0.4 s) before it; a later one may follow its predecessor's stroke too closely to prepare
("no room"), or only by a blend that would collide. The timeline already compresses preparations as far as
the joint speed bound allows, so more time scaling cannot help. Policy (pipeline.stages.schedule.softening),
which keeps both the pre-roll and the speed bound: each gesture the timeline plans late (its stroke more
than `late_tolerance_s` after its aim) or drops for lack of room is tried, in word order, at each lower
intensity in turn, down to `lowest_intensity`: its interior keyframes pulled toward its start pose by
gains[lower] / gains[requested] (Eq. intensity's gains, shared with the modulate stage; a point between two
poses inside the limits stays inside them, and an aimed pose keeps its direction). A smaller excursion is a
shorter preparation under the speed bound, and a blend that stays further from the other arm. The first
intensity that fits replaces the gesture: its timing's fit is "softened" and its record carries the
intensity played, so the schedule, the recording and the web UI show what was chosen. If none fits, the
requested gesture is kept (late, or dropped with the timeline's reason). Lateness counts only for a stroke
aimed at a word: a named gesture (released at once) or one spread over a reply without its trigger has no
word to be late for, so it is softened only when it would be dropped.
A first gesture that starts away from rest (after the thinking gesture) is planned from the arm's pose by
the timeline itself (`arm`), so this policy sees its true preparation.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from emopose.stages.modulate import INTENSITY_GAINS, scale_excursion
from emopose.turn.model import GestureTiming, ModulatedGesture
from emopose.turn.timeline import TimelinePlanner


@dataclass(frozen=True)
class SofteningSettings:
    lowest_intensity: int = 1  # the softest a gesture that does not fit may be played; 5 (or above) = off
    # A stroke planned at most this long after its aim counts as on time (the stroke window reaches 150 ms
    # past the aim: lead -50 ms, window +100 ms), so a gesture is not softened for a few milliseconds.
    late_tolerance_s: float = 0.05
    # The YAML takes the modulate stage's; None (no modulate node: an ablated pipeline, which the order
    # check then refuses with its own message) means modulate's default gains.
    gains: tuple[float, ...] | None = INTENSITY_GAINS

    def __post_init__(self) -> None:
        if self.gains is None:
            object.__setattr__(self, "gains", INTENSITY_GAINS)
        if len(self.gains) != 5 or min(self.gains) <= 0:
            raise ValueError(f"softening.gains needs 5 positive values, got {self.gains}")
        if self.late_tolerance_s < 0:
            raise ValueError(f"softening.late_tolerance_s must be >= 0, got {self.late_tolerance_s}")

    def fits(self, timing: GestureTiming | str, on_word: bool = True) -> bool:
        """Placed, and (aimed at a word) its stroke arrives on time (within the tolerance)."""
        if isinstance(timing, str):
            return False
        on_time = timing.fit != "late" or timing.arrival_s <= timing.target_s + self.late_tolerance_s
        return on_time or not on_word


def softened(gesture: ModulatedGesture, intensity: int, gains: tuple[float, ...]) -> ModulatedGesture:
    """`gesture` at a lower `intensity`: interior keyframes pulled toward the start pose."""
    q = scale_excursion(gesture.keyframes, gains[intensity - 1] / gains[gesture.intensity - 1])
    record = gesture.resolved.record.model_copy(update={"intensity": intensity})
    return replace(gesture, resolved=replace(gesture.resolved, record=record), keyframes=q)


def plan_softening(planner: TimelinePlanner, gestures: list[ModulatedGesture], onsets: list[float],
                   arm: np.ndarray | None, settings: SofteningSettings, on_word: list[bool] | None = None
                   ) -> tuple[list[ModulatedGesture], list[GestureTiming | str], float]:
    """The gestures as played (some perhaps softened), their timings (or drop reasons), the pre-roll.
    Gestures are fitted in word order, so a softened one is settled before those after it are tried.
    `on_word[k]`: gesture k's onset is its trigger word's (None: every gesture's is)."""
    on_word = on_word or [True] * len(gestures)
    placed, preroll = planner.plan(gestures, onsets, arm)
    for k in sorted(range(len(gestures)), key=lambda k: onsets[k]):
        if settings.fits(placed[k], on_word[k]):
            continue
        for intensity in range(gestures[k].intensity - 1, settings.lowest_intensity - 1, -1):
            trial = list(gestures)
            trial[k] = softened(gestures[k], intensity, settings.gains)
            out, trial_preroll = planner.plan(trial, onsets, arm)
            if settings.fits(out[k], on_word[k]):
                out[k] = replace(out[k], fit="softened")
                gestures, placed, preroll = trial, out, trial_preroll
                break
    return gestures, placed, preroll
