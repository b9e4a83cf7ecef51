"""What the robot knows about its surroundings when it plans a gesture: objects and its own pose.

The tour keeps the run's SceneSlot up to date (the current stop's objects, the odometry pose); the aim
stage, which holds the same slot, asks its view which object a pointing record means: one the trigger
(or the sentence around it) names, else the stop's designated or only object. With an empty slot (no
tour) nothing is aimed.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from emopose.scene.geometry import Pose2D, map_to_torso
from emopose.sentences import sentence_span


@dataclass(frozen=True)
class SceneObject:
    name: str
    position: np.ndarray  # map frame (3,)
    words: tuple[str, ...] = ()  # names in speech: "introduction board", "the board"

    def mentioned_in(self, text: str) -> bool:
        lowered = text.lower()
        return any(re.search(rf"(?<![\w]){re.escape(w.lower())}(?![\w])", lowered) for w in self.words if w)


@dataclass
class SceneView:
    base: Pose2D
    objects: list[SceneObject] = field(default_factory=list)
    focus: str | None = None  # the stop's default target (its point_at or its only object)
    at_stop: bool = True
    aims: list = field(default_factory=list)  # AimReports of the gestures aimed in this view

    @classmethod
    def at(cls, base: Pose2D, stop, everything: list | None = None) -> SceneView:
        """The view at a tour stop: its objects first (others still resolve by name), its focus."""
        own = [_object(o) for o in stop.objects]
        others = [_object(o) for o in (everything or []) if o.name not in {s.name for s in own}]
        focus = stop.point_at or (stop.objects[0].name if len(stop.objects) == 1 else None)
        return cls(base, own + others, focus, True)

    @classmethod
    def walking(cls, base: Pose2D, everything: list) -> SceneView:
        """Between stops: objects resolve only when named; there is no default target."""
        return cls(base, [_object(o) for o in everything], None, False)

    def get(self, name: str) -> SceneObject | None:
        return next((o for o in self.objects if o.name == name), None)

    def target_for(self, trigger: str | None, reply: str = "") -> SceneObject | None:
        """The object a pointing record at `trigger` in `reply` refers to, or None."""
        for text in (trigger or "", _sentence_around(reply, trigger)):
            named = [o for o in self.objects if text and o.mentioned_in(text)]
            if named:
                return named[0]
        return self.get(self.focus) if self.focus else None

    def in_torso(self, obj: SceneObject) -> np.ndarray:
        return map_to_torso(obj.position, self.base)


def _object(spec) -> SceneObject:
    return SceneObject(spec.name, np.asarray(spec.position, dtype=float), spec.words())


def _sentence_around(reply: str, trigger: str | None) -> str:
    pos = reply.lower().find(trigger.lower()) if trigger and reply else -1
    if pos < 0:
        return ""
    start, end = sentence_span(reply, pos)
    return reply[start:end]


@dataclass
class SceneSlot:
    """The view the robot plans in right now: set by whoever knows the surroundings (the tour), read by
    the aim stage; None when nobody does."""

    view: SceneView | None = None
