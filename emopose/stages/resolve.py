"""Resolve: each record -> a library entry, by the paper's resolver (Eq. resolver).

rho(c, v) = l_v if v is a loaded name; else the class default l_c^(0) if class c has motions; else
l_neutral. The result keeps the requested and resolved names so class-variant agreement is auditable.
Optional confidence gating (off by default, beyond the paper): a record below the threshold resolves to
its class default or to neutral instead of its named variant.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from typing import Literal

from emopose.contract import GestureRecord
from emopose.library import MotionLibrary
from emopose.turn.model import ResolvedGesture, Turn

log = logging.getLogger(__name__)


def resolve_record(record: GestureRecord, library: MotionLibrary) -> ResolvedGesture:
    """The paper's resolver, exactly."""
    if record.variant is not None:
        entry = library.get(record.variant)
        if entry is not None:
            return ResolvedGesture(record, entry, "exact")
    default = library.class_default(record.cls)
    if default is not None:
        return ResolvedGesture(record, default, "class_default")
    return ResolvedGesture(record, library.neutral_entry, "neutral")


@dataclass
class Resolve:
    """Stage: plan -> resolved gestures. `min_confidence` enables gating; `gate_to` picks the fallback.

    The library is the live one: a motion saved in Pose Studio a moment ago resolves at once."""

    library: MotionLibrary = field(repr=False)
    min_confidence: float | None = None
    gate_to: Literal["class_default", "neutral"] = "class_default"
    name = "resolve"
    reads = ("plan",)
    writes = ("resolved",)

    def __post_init__(self) -> None:
        if self.min_confidence is not None and not 0.0 <= self.min_confidence <= 1.0:
            raise ValueError(f"pipeline.resolve.min_confidence must be in [0, 1], got {self.min_confidence}")

    def __call__(self, turn: Turn) -> list[ResolvedGesture]:
        return [self.resolve(record) for record in turn.plan.records]

    def resolve(self, record: GestureRecord) -> ResolvedGesture:
        log.info("record %s/%s confidence %.2f", record.cls, record.variant, record.confidence)
        if self.min_confidence is None or record.confidence >= self.min_confidence:
            return resolve_record(record, self.library)
        fallback = self.library.class_default(record.cls) if self.gate_to == "class_default" else None
        return ResolvedGesture(record, fallback or self.library.neutral_entry, "gated")
