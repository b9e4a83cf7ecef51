"""Schedule: gestures against speech (Eq. schedule, lexical anchors; or a stroke-synchronous timeline).

anchor mode (the paper): the first occurrence of trigger t_k in reply r releases at
    tau_k = (pos(t_k; r) + |t_k| / 2) / max(|r|, 1) * T_a.
Missing anchors are interpolated between the neighbouring matches (0 and T_a act as the outer
neighbours); if no trigger matches, release k is at T_a (k + 1/2) / M_g, and a lone gesture is
released at once. words mode uses the synthesizer's true onset of the trigger's first word and falls
back to the anchor equation where it has no word timings. Trigger search is case-insensitive.
timeline mode (the default, beyond the paper) takes the words-mode times as the onsets the strokes must
meet and plans every gesture's keyframe times around them (emopose/turn/timeline.py); its release is the
gesture's start, possibly before the speech (the pre-roll); the sequencer's published pose tells it
where the arm is, so a first gesture that starts away from rest still lands on its word; a gesture that
would land late or find no room is played softer where that fits (`softening`, emopose/stages/softening.py).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np

from emopose.contract import trigger_position
from emopose.execution.sequencer import Sequencer
from emopose.execution.trajectory import TrajectoryBuilder
from emopose.joint_limits import JointLimits
from emopose.speech.clip import SpeechClip, Synthesizer
from emopose.stages.softening import SofteningSettings, plan_softening
from emopose.turn.model import ON_WORD_RULES, Release, ReleaseRule, Schedule, Turn
from emopose.turn.timeline import TimelinePlanner, TimelineSettings

MODES = ("anchor", "words", "timeline")

log = logging.getLogger(__name__)

def anchor_release_times(reply: str, triggers: list[str | None],
                         duration_s: float) -> list[tuple[float, ReleaseRule]]:
    """The paper's schedule equation with its interpolation and even-spacing rules."""
    count = len(triggers)
    length = max(len(reply), 1)
    matched: dict[int, float] = {}
    for k, trigger in enumerate(triggers):
        pos = trigger_position(reply, trigger)
        if pos is not None:
            matched[k] = (pos + len(trigger) / 2) / length * duration_s
    if not matched:
        if count == 1:
            return [(0.0, "immediate")]
        return [(duration_s * (k + 0.5) / count, "even") for k in range(count)]
    anchors = sorted(matched.items())
    out: list[tuple[float, ReleaseRule]] = []
    for k in range(count):
        if k in matched:
            out.append((matched[k], "anchor"))
            continue
        before = max(((i, t) for i, t in anchors if i < k), default=(-1, 0.0))
        after = min(((i, t) for i, t in anchors if i > k), default=(count, duration_s))
        frac = (k - before[0]) / (after[0] - before[0])
        out.append((before[1] + frac * (after[1] - before[1]), "interpolated"))
    return out


def word_release_times(reply: str, triggers: list[str | None],
                       speech: SpeechClip) -> list[tuple[float, ReleaseRule]]:
    """True word onsets where the trigger is found and the synthesizer gave word timings."""
    out = anchor_release_times(reply, triggers, speech.duration_s)
    for k, trigger in enumerate(triggers):
        pos = trigger_position(reply, trigger)
        onset = speech.onset_at_char(pos) if pos is not None else None
        if onset is not None:
            out[k] = (onset, "words")
    return out


@dataclass
class ScheduleStage:
    """Stage: plan + modulated -> speech + schedule. Its synthesizer gives the reply's audio, T_a and
    word onsets; `limits` bound the timeline's joint speeds (the same bound the sequencer builds with) and
    `safety` (the sequencer's check) vets its co-articulation blends; `sequencer` (read only) tells the
    timeline where the arm is."""

    synthesizer: Synthesizer = field(repr=False)
    limits: JointLimits = field(repr=False)
    safety: Callable[[np.ndarray], str | None] | None = field(default=None, repr=False)
    sequencer: Sequencer | None = field(default=None, repr=False)
    mode: Literal["anchor", "words", "timeline"] = "timeline"
    timeline: TimelineSettings = field(default_factory=TimelineSettings)
    softening: SofteningSettings = field(default_factory=SofteningSettings)
    name = "schedule"
    reads = ("plan", "modulated")
    writes = ("speech", "schedule")

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise ValueError(f"pipeline.schedule.mode must be one of {MODES}, got {self.mode!r}")
        self._planner = TimelinePlanner(TrajectoryBuilder(self.limits), self.timeline, self.safety)

    def in_mode(self, mode: str) -> ScheduleStage:
        """A copy that schedules in `mode` (sync_eval measures every mode with one configuration)."""
        return replace(self, mode=mode)

    def with_preroll_at_most(self, preroll_s: float) -> ScheduleStage:
        """This stage with the timeline's pre-roll bounded by `preroll_s` (itself when already within)."""
        if self.timeline.max_preroll_s <= preroll_s:
            return self
        return replace(self, timeline=replace(self.timeline, max_preroll_s=preroll_s))

    def __call__(self, turn: Turn) -> tuple[SpeechClip, Schedule]:
        reply = turn.plan.reply
        speech = self.synthesizer.synthesize(reply)
        triggers = [m.resolved.record.trigger for m in turn.modulated]
        times = (anchor_release_times(reply, triggers, speech.duration_s) if self.mode == "anchor"
                 else word_release_times(reply, triggers, speech))
        found = [trigger_position(reply, trig) is not None for trig in triggers]
        for k in [k for k, ok in enumerate(found) if not ok and triggers[k]]:
            log.warning("say-do check: trigger %r of record %d is not in the reply", triggers[k], k)
        if self.mode != "timeline":
            releases = tuple(Release(t, how, ok) for (t, how), ok in zip(times, found))
            return speech, Schedule(reply, releases, tuple(turn.modulated))
        arm = None if self.sequencer is None else self.sequencer.last
        onsets = [t for t, _ in times]
        on_word = [how in ON_WORD_RULES for _, how in times]
        gestures, placed, preroll = plan_softening(self._planner, list(turn.modulated), onsets, arm,
                                                   self.softening, on_word)
        releases = tuple(
            Release(timing.times[0], how, ok, timing=timing) if not isinstance(timing, str)
            else Release(t, how, ok, dropped=timing)
            for timing, (t, how), ok in zip(placed, times, found))
        for k, release in enumerate(releases):
            if release.dropped:
                log.info("timeline: gesture %d (%s) dropped: %s", k, gestures[k].name, release.dropped)
            elif release.timing.fit == "softened" or release.timing.fit.startswith("via_"):
                log.info("timeline: gesture %d (%s) fitted %s at intensity %d", k, gestures[k].name,
                         release.timing.fit, gestures[k].intensity)
        return speech, Schedule(reply, releases, tuple(gestures), preroll)
