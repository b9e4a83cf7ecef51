"""The semantic contract: what a planner may say (records, plans) and what the robot owns (library entries).

Values that cross the model boundary are pydantic models validated once, where they enter.
The model never supplies a joint value: `LibraryEntry.keyframes` only ever come from library files.
"""

from __future__ import annotations

from collections.abc import Sequence
from enum import StrEnum
from typing import Annotated, Literal

import numpy as np
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    PrivateAttr,
    StringConstraints,
    ValidationInfo,
    create_model,
    field_validator,
    model_validator,
)

from emopose import CLASSES, CONTROL_DT, NUM_JOINTS

GestureClass = Literal[
    "pointing", "emphasizing", "rejecting", "agreeing", "doubting", "welcoming", "comforting", "neutral"
]
# Where a plan's records came from. Usable: the model's own records (first try, or after transient
# retries), or a script (no planner). Every other source is a fallback the benchmarks count: chatter
# (plain_text), nothing (empty), a class outside the eight (unknown_class), no records (no_records),
# JSON no parser could use (keyword_fallback), or no answer at all (call_failed: the call failed for good).
PlanSource = Literal["model", "retried", "scripted", "plain_text", "empty", "unknown_class", "no_records",
                     "keyword_fallback", "call_failed"]
USABLE_SOURCES = frozenset({"model", "retried", "scripted"})

MIN_KEYFRAMES, MAX_KEYFRAMES = 3, 14
MAX_DURATION_S = 20.0  # the longest motion a library entry may state (its duration or last keyframe time)
MAX_EXAMPLES = 8  # example utterances a motion file may carry
# The longest text of a record (the parser cuts a trigger or variant to it at a word), and the piece a
# tour line is planned in (whole sentences under it); a reply keeps more (stages/parse.py MAX_SPOKEN_CHARS).
MAX_REPLY_CHARS = 200
# What a record's trigger is (README "The planner's contract"; the schema's description says it to a model)
TRIGGER_RULE = ("the words the gesture belongs to (its lexical affiliate: the place pointed at, the stressed "
                "words, the yes or greeting itself, a refusal's own words after any 'No,' before them, a "
                "doubt's hedge rather than the question it answers, the reassurance itself rather than a "
                "'Don't worry,' before it, never an 'Oh,' or a name called before the words), 1-6 words "
                "copied exactly from the reply; its first word is where the stroke lands, so it starts "
                "there, not at the clause around it")


class EventKind(StrEnum):
    """What the sequencer reports of a gesture (emopose/execution/sequencer.py); recordings
    (/sequencer/events), Turn.to_json and the sync measurement keep the string values."""

    STARTED = "started"
    STROKE = "stroke"  # the arm reached the stroke (measured joints where the backend measures them)
    STROKE_COMMANDED = "stroke_commanded"  # the command stream reached it (only beside a measured STROKE)
    COMPLETED = "completed"
    CUT = "cut"  # ended after its stroke: co-articulated into, or preempted by, the next gesture
    STOPPED = "stopped"  # interrupted, or cut short by an overdue successor
    REJECTED = "rejected"  # refused by the safety check
    DROPPED = "dropped"  # the timeline could not fit it
    STATE = "state"  # the sequencer's state changed (detail: the new state)
    POSTURE = "posture"  # the arms head for another posture between gestures (detail: its name; posture.py)


def trigger_position(reply: str, trigger: str | None) -> int | None:
    """Where a record's trigger starts in the reply (case-insensitive, first occurrence), or None."""
    if not trigger:
        return None
    pos = reply.lower().find(trigger.lower())
    return pos if pos >= 0 else None


class GestureRecord(BaseModel):
    """One semantic record z_k = (class, variant, intensity, trigger, confidence) (paper Eq. record)."""

    model_config = ConfigDict(frozen=True, populate_by_name=True)

    cls: GestureClass = Field(alias="class")
    variant: str | None = None
    intensity: int = Field(default=3, ge=1, le=5)
    trigger: str | None = None
    confidence: float = Field(default=1.0, ge=0.0, le=1.0)

    def as_json(self) -> dict:
        return self.model_dump(by_alias=True)


class Plan(BaseModel):
    """A verbal reply and its ordered gesture records, plus how the parser obtained them."""

    model_config = ConfigDict(frozen=True)

    reply: str
    records: tuple[GestureRecord, ...]
    source: PlanSource = "model"
    notes: tuple[str, ...] = ()

    @property
    def fallback(self) -> bool:
        """True when the records are not a usable model (or scripted) record."""
        return self.source not in USABLE_SOURCES

    @property
    def top_class(self) -> str:
        return self.records[0].cls if self.records else "neutral"

    @classmethod
    def scripted(cls, reply: str, *records: GestureRecord) -> Plan:
        """A plan written by code (a suite item, a robot check, a button), not by a planner."""
        return cls(reply=reply, records=records, source="scripted")


def plan_schema(variants: Sequence[str], max_gestures: int) -> dict:
    """The JSON schema of a planner's answer, generated from GestureRecord: the eight classes, the live
    library's variant names as an enum, every field required and nothing else allowed (what OpenAI's
    strict structured output and llama.cpp's grammar both accept)."""
    if not variants:
        raise ValueError("plan_schema needs at least one library variant")
    strict = ConfigDict(extra="forbid", populate_by_name=True)
    record = create_model(
        "GestureRecord", __config__=strict, __doc__=GestureRecord.__doc__,
        cls=(GestureClass, Field(alias="class")), variant=(Literal[tuple(variants)], ...),
        intensity=(int, Field(ge=1, le=5)), trigger=(str, Field(description=TRIGGER_RULE)),
        confidence=(float, Field(ge=0.0, le=1.0)))
    answer = create_model("GesturePlan", __config__=strict, reply=(str, ...),
                          gestures=(list[record], Field(min_length=1, max_length=max_gestures)))
    return answer.model_json_schema(by_alias=True)


MotionType = Literal["sequence", "pose"]
ExampleUtterance = Annotated[str, StringConstraints(strip_whitespace=True, min_length=3,
                                                    max_length=MAX_REPLY_CHARS)]


class LibraryEntry(BaseModel):
    """One robot-owned motion l_n = (name, class, keyframes Q, duration d, motion type m)
    (paper Eq. library)."""

    model_config = ConfigDict(frozen=True, populate_by_name=True, extra="forbid")

    name: str = Field(pattern=r"^[a-z][a-z0-9_]{1,63}$")
    cls: GestureClass = Field(alias="class")
    description: str = Field(min_length=3, max_length=200)
    motion_type: MotionType = "sequence"
    duration: float | None = Field(default=None, gt=0.0, le=MAX_DURATION_S)
    keyframes: tuple[tuple[float, ...], ...]
    # Sync points (BML's stroke_start, stroke_end) as keyframe indices: where the expressive part of the
    # motion begins and ends. The timeline puts the stroke start on the trigger word.
    stroke: tuple[int, int] | None = None
    # When each keyframe is reached, s from the motion's start (times[0] = 0; the last is the duration).
    # Without it the keyframes are evenly spaced over the duration.
    times: tuple[float, ...] | None = None
    # A few utterances the motion fits, read by the local planner next to the description (no retraining)
    examples: tuple[ExampleUtterance, ...] = Field(default=(), max_length=MAX_EXAMPLES)
    _q: np.ndarray = PrivateAttr()

    @field_validator("keyframes")
    @classmethod
    def _shape(cls, frames: tuple[tuple[float, ...], ...]) -> tuple[tuple[float, ...], ...]:
        for k, frame in enumerate(frames):
            if len(frame) != NUM_JOINTS:
                raise ValueError(f"keyframe {k} has {len(frame)} values; every keyframe needs {NUM_JOINTS}")
            if not all(np.isfinite(frame)):
                raise ValueError(f"keyframe {k} contains a non-finite value")
        return frames

    @field_validator("times")
    @classmethod
    def _timed(cls, times: tuple[float, ...] | None, info: ValidationInfo) -> tuple[float, ...] | None:
        if times is None:
            return None
        if info.data.get("motion_type") == "pose":
            raise ValueError("a pose has no keyframe times; give its duration instead")
        if info.data.get("duration") is not None:
            raise ValueError("give times or duration, not both (the last keyframe's time is the duration)")
        count = len(info.data.get("keyframes", times))
        if len(times) != count:
            raise ValueError(f"{len(times)} times for {count} keyframes; give one time per keyframe")
        if times[0] != 0.0:
            raise ValueError(f"times[0] is {times[0]}; keyframe 0 is where the motion starts, at 0 s")
        for k in range(1, len(times)):
            if not times[k] - times[k - 1] >= CONTROL_DT - 1e-9:  # also refuses NaN
                raise ValueError(f"K{k} at {times[k]} s must come at least {CONTROL_DT} s (one control tick) "
                                 f"after K{k - 1} at {times[k - 1]} s")
        if times[-1] > MAX_DURATION_S:
            raise ValueError(f"the last keyframe at {times[-1]} s: a motion lasts at most {MAX_DURATION_S} s")
        return times

    @model_validator(mode="after")
    def _count(self) -> LibraryEntry:
        k = len(self.keyframes)
        if self.motion_type == "pose" and k != 1:
            raise ValueError(f"a pose has exactly 1 keyframe, got {k}")
        if self.motion_type == "sequence" and not MIN_KEYFRAMES <= k <= MAX_KEYFRAMES:
            raise ValueError(
                f"a sequence needs {MIN_KEYFRAMES}..{MAX_KEYFRAMES} keyframes "
                f"(at least one interior), got {k}"
            )
        self._q = np.asarray(self.keyframes, dtype=float)
        self._q.setflags(write=False)
        if self.stroke is not None:
            start, end = self.stroke
            first, last = (0, 0) if self.motion_type == "pose" else (1, k - 2)
            if not first <= start <= end <= last:
                raise ValueError(f"stroke {list(self.stroke)} must satisfy {first} <= start <= end <= {last} "
                                 f"(interior keyframe indices of this {self.motion_type})")
        return self

    @property
    def q(self) -> np.ndarray:
        """Keyframes as a read-only (K, 14) array in radians."""
        return self._q

    @property
    def stroke_span(self) -> tuple[int, int]:
        """The declared stroke, else the documented default: the interior keyframe of largest excursion
        from the first (max over joints), as a single apex."""
        if self.stroke is not None:
            return self.stroke
        if self.motion_type == "pose":
            return (0, 0)
        apex = 1 + int(np.argmax(np.abs(self._q[1:-1] - self._q[0]).max(axis=1)))
        return (apex, apex)

    @property
    def default_duration(self) -> float:
        """Paper Eq. duration: d(Q) = clip(0.3 (K - 1), 1, 5) s, unless the entry sets one explicitly (its
        duration, or its last keyframe time)."""
        if self.duration is not None:
            return self.duration
        if self.times is not None:
            return self.times[-1]
        return float(np.clip(0.3 * (len(self.keyframes) - 1), 1.0, 5.0))


assert tuple(GestureClass.__args__) == CLASSES  # one list of classes, in the paper's order
