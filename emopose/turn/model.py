"""One utterance's way to joint commands: the typed value of every arrow, and the Turn that holds them.

request -> planner_output -> plan -> resolved -> modulated -> speech + schedule -> submitted -> dispatched.
Each stage declares the fields it reads and writes (emopose/turn/pipeline.py checks the order); the values
live here, together, so no stage imports another. `Turn.to_json()` is the one serialisation that feeds
the MCAP recording, the web UI and results.json.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Literal

import numpy as np

from emopose.contract import GestureRecord, LibraryEntry, Plan
from emopose.execution.gesture_command import Event, GestureCommand
from emopose.planners.base import PlannerOutput, PlanRequest
from emopose.speech.clip import SpeechClip

ResolveRule = Literal["exact", "class_default", "neutral", "gated"]
ReleaseRule = Literal["anchor", "words", "interpolated", "even", "immediate"]
ON_WORD_RULES = ("anchor", "words")  # the rules that aim at the trigger's own words (the others: no word)
Fit = Literal["nominal", "scaled", "direct", "coarticulated", "shortened", "softened", "via_halfway",
              "via_rest", "via_apart", "late"]


@dataclass(frozen=True)
class ResolvedGesture:
    """A record and the library entry the resolver chose for it, with the rule that chose it."""

    record: GestureRecord
    entry: LibraryEntry
    rule: ResolveRule

    @property
    def requested(self) -> str | None:
        return self.record.variant

    @property
    def class_agrees(self) -> bool:
        return self.entry.cls == self.record.cls

    def as_json(self) -> dict:
        return {"class": self.record.cls, "requested": self.requested, "resolved": self.entry.name,
                "resolved_class": self.entry.cls, "rule": self.rule, "confidence": self.record.confidence}


@dataclass(frozen=True)
class ModulatedGesture:
    """A resolved gesture with its intensity-scaled (K, 14) keyframes and (unchanged) duration in s."""

    resolved: ResolvedGesture
    keyframes: np.ndarray
    duration: float

    @property
    def name(self) -> str:
        return self.resolved.entry.name

    @property
    def intensity(self) -> int:
        return self.resolved.record.intensity

    def as_json(self) -> dict:
        return {"name": self.name, "intensity": self.intensity, "duration_s": self.duration,
                "keyframes": np.round(self.keyframes, 5).tolist()}


@dataclass(frozen=True)
class GestureTiming:
    """A gesture on the timeline, in s from the start of speech: keyframes[0..n] (n = len(times) - 1,
    after any cut) are reached at `times`; keyframe 0 is the start pose, whatever is published then.
    `stroke` holds keyframe indices; the stroke is aimed to arrive (come within the tolerance of the
    stroke-start keyframe) at `target_s`, and is planned to arrive at `arrival_s`."""

    keyframes: np.ndarray
    times: tuple[float, ...]
    stroke: tuple[int, int]
    target_s: float
    arrival_s: float
    fit: Fit
    blend_in: bool = False      # first segment blends from the previous gesture's stroke (co-articulation)
    scale: float = 1.0          # time scale of the preparation
    cut: bool = False           # ends after its stroke: the next gesture co-articulates from there

    def as_json(self) -> dict:
        return {"times": [round(t, 4) for t in self.times], "stroke": list(self.stroke),
                "target_s": self.target_s, "arrival_s": self.arrival_s, "fit": self.fit,
                "blend_in": self.blend_in, "scale": self.scale, "cut": self.cut}


@dataclass(frozen=True)
class Release:
    """When gesture k is released, relative to the start of speech, and which rule placed it. A timeline
    schedule adds the gesture's timing, or why it was dropped."""

    release_s: float
    how: ReleaseRule
    trigger_found: bool
    timing: GestureTiming | None = None
    dropped: str | None = None


@dataclass(frozen=True)
class Schedule:
    reply: str
    releases: tuple[Release, ...]
    gestures: tuple[ModulatedGesture, ...]
    preroll_s: float = 0.0  # speech starts this much after the first gesture may (timeline mode)

    @property
    def missing_triggers(self) -> list[int]:
        """Indices of records whose trigger is not in the reply (the say-do check)."""
        return [k for k, r in enumerate(self.releases) if not r.trigger_found]

    def as_json(self) -> dict:
        return {"preroll_s": self.preroll_s, "releases": [
            {"name": g.name, "intensity": g.intensity, "release_s": r.release_s, "how": r.how,
             "trigger_found": r.trigger_found,
             "dropped": r.dropped, "timing": None if r.timing is None else r.timing.as_json()}
            for g, r in zip(self.gestures, self.releases)]}


@dataclass(frozen=True)
class Submission:
    """The commands handed to the sequencer, the planned speech start (control clock), hand-off times, and
    when dispatch should start the audio (after the timeline's pre-roll)."""

    commands: tuple[GestureCommand, ...]
    speech_start: float
    submission_s: tuple[float, ...]
    play_at: float = float("-inf")

    def as_json(self) -> dict:
        return {"speech_start": self.speech_start, "play_at": self.play_at,
                "submission_s": list(self.submission_s),
                "commands": [{"id": c.id, "record": c.record, "name": c.name, "release_at": c.release_at,
                              "duration_s": c.duration, "label": c.label} for c in self.commands]}


@dataclass(frozen=True)
class DispatchReport:
    """What execution did: whether it reached the awaited state, the sequencer's events, ticks run, and
    when the speech audio actually started on the control clock."""

    completed: bool
    events: tuple[Event, ...]
    ticks: int
    speech_start: float

    def as_json(self) -> dict:
        return {"completed": self.completed, "ticks": self.ticks, "speech_start": self.speech_start,
                "events": [{"t": e.t, "kind": e.kind, "name": e.name, "command_id": e.command_id,
                            "detail": e.detail} for e in self.events]}


def _speech_json(clip: SpeechClip) -> dict:
    return {"text": clip.text, "duration_s": clip.duration_s, "estimated": clip.estimated,
            "audio": None if clip.audio_path is None else str(clip.audio_path),
            "words": [{"text": w.text, "char_start": w.char_start, "start_s": w.start_s} for w in clip.words]}


def _json(value: object) -> object:
    if isinstance(value, PlanRequest):
        return {"utterance": value.utterance, "history_messages": len(value.history),  # on /dialogue
                "image": value.image is not None}
    if isinstance(value, PlannerOutput):
        return {"raw": value.raw, "latency_s": value.latency_s, "fallback": value.fallback,
                "error": value.error, "meta": value.meta}
    if isinstance(value, Plan):
        return {"reply": value.reply, "source": value.source, "notes": list(value.notes),
                "records": [r.as_json() for r in value.records]}
    if isinstance(value, SpeechClip):
        return _speech_json(value)
    if isinstance(value, (list, tuple)):
        return [_json(v) for v in value]
    return value.as_json()


@dataclass
class Turn:
    """Everything one utterance produces on its way to joint commands; stages fill the fields in order."""

    request: PlanRequest
    planner_output: PlannerOutput | None = None
    plan: Plan | None = None
    resolved: list[ResolvedGesture] | None = None
    modulated: list[ModulatedGesture] | None = None
    speech: SpeechClip | None = None
    schedule: Schedule | None = None
    submitted: Submission | None = None
    dispatched: DispatchReport | None = None
    stage_s: dict[str, float] = field(default_factory=dict)

    @classmethod
    def field_names(cls) -> tuple[str, ...]:
        """The fields a stage may read or write (stage_s is the pipeline's own timing)."""
        return tuple(f.name for f in fields(cls) if f.name != "stage_s")

    def performs_nothing(self) -> bool:
        """No words to say and every gesture dropped (a named gesture the schedule cannot fit): the
        sequence and dispatch stages then leave what the robot is doing alone instead of stopping it."""
        return not self.speech.text.strip() and all(r.dropped for r in self.schedule.releases)

    def field_json(self, name: str) -> object:
        value = getattr(self, name)
        return None if value is None else _json(value)

    def to_json(self) -> dict:
        out = {name: self.field_json(name) for name in self.field_names() if getattr(self, name) is not None}
        out["stage_ms"] = {k: v * 1e3 for k, v in self.stage_s.items()}
        return out
