"""Schedule: release times against speech (Eq. schedule, lexical anchors).

anchor mode (the paper): the first occurrence of trigger t_k in reply r releases at
    tau_k = (pos(t_k; r) + |t_k| / 2) / max(|r|, 1) * T_a.
Missing anchors are interpolated between the neighbouring matches (0 and T_a act as the outer
neighbours); if no trigger matches, release k is at T_a (k + 1/2) / M_g, and a lone gesture is
released at once. words mode uses the synthesizer's true onset of the trigger's first word and falls
back to the anchor equation where it has no word timings. Trigger search is case-insensitive.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from typing import Literal

from emopose.speech.clip import SpeechClip, Synthesizer
from emopose.turn import Release, ReleaseRule, Schedule, Turn

log = logging.getLogger(__name__)

def trigger_position(reply: str, trigger: str | None) -> int | None:
    if not trigger:
        return None
    pos = reply.lower().find(trigger.lower())
    return pos if pos >= 0 else None


def anchor_release_times(reply: str, triggers: list[str | None], duration_s: float) -> list[tuple[float, ReleaseRule]]:
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


def word_release_times(reply: str, triggers: list[str | None], speech: SpeechClip) -> list[tuple[float, ReleaseRule]]:
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
    word onsets."""

    synthesizer: Synthesizer = field(repr=False)
    mode: Literal["anchor", "words"] = "anchor"
    name = "schedule"
    reads = ("plan", "modulated")
    writes = ("speech", "schedule")

    def __post_init__(self) -> None:
        if self.mode not in ("anchor", "words"):
            raise ValueError(f"pipeline.schedule.mode must be 'anchor' or 'words', got {self.mode!r}")

    def __call__(self, turn: Turn) -> tuple[SpeechClip, Schedule]:
        reply = turn.plan.reply
        speech = self.synthesizer.synthesize(reply)
        triggers = [m.resolved.record.trigger for m in turn.modulated]
        times = (word_release_times(reply, triggers, speech) if self.mode == "words"
                 else anchor_release_times(reply, triggers, speech.duration_s))
        releases = tuple(
            Release(t, how, trigger_position(reply, trig) is not None) for (t, how), trig in zip(times, triggers)
        )
        for k in [k for k, r in enumerate(releases) if not r.trigger_found and triggers[k]]:
            log.warning("say-do check: trigger %r of record %d is not in the reply", triggers[k], k)
        return speech, Schedule(reply, releases, tuple(turn.modulated))
