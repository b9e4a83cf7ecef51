"""What the sequencer is handed (a GestureCommand) and what it reports (an Event, its State).

A command is a motion to run: intensity-modulated keyframes, a duration and an earliest start on the
control clock (the paper's FIFO-with-release behaviour); a timed command (the timeline) also fixes
every keyframe's time. Events name the command they concern.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from enum import StrEnum

import numpy as np

from emopose.contract import EventKind


@dataclass(frozen=True)
class GestureCommand:
    """A motion to run: intensity-modulated (K, 14) keyframes, duration, earliest start (clock time).
    A timed command also gives each keyframe's time after release_at (`offsets`, offsets[0] = 0)."""

    name: str
    keyframes: np.ndarray
    duration: float
    release_at: float = float("-inf")
    label: str = ""
    id: int = field(default_factory=itertools.count().__next__)
    record: int | None = None               # index of the plan record it performs, when it comes from a turn
    stroke: tuple[int, int] | None = None   # keyframe indices of the stroke, for the "stroke" event
    offsets: tuple[float, ...] | None = None
    authored_times: tuple[float, ...] | None = None  # untimed: the motion's own keyframe times (`times:`)
    blend_in: bool = False                  # timed: the first segment is a co-articulation blend
    cut: bool = False                       # timed: planned to end after its stroke (reported as CUT)

    @property
    def timed(self) -> bool:
        return self.offsets is not None


class State(StrEnum):
    """The sequencer's state. Its transitions (emopose/execution/sequencer.py):

    IDLE/HOLDING --released command--> EXECUTING (trajectory built from the latest published pose)
    EXECUTING --done, successor released--> BLENDING (cubic, <= blend_s) --> EXECUTING
    EXECUTING --done, nothing released--> HOLDING --hold_s, endpoint not home--> BLENDING home
                                                    (recover_s) --> IDLE
    any --interrupt--> pending cleared, BLENDING (interrupt_blend_s) toward the new target --> EXECUTING
    EXECUTING --stall, stroke too late--> BLENDING home (recover_s)
    IDLE/HOLDING (nothing queued) or BLENDING home --posture changed--> BLENDING to it (transition_s)
    "home" is the current posture (rest, listening, thinking: posture.py), neutral without one.
    """

    IDLE = "idle"
    EXECUTING = "executing"
    HOLDING = "holding"
    BLENDING = "blending"


@dataclass(frozen=True)
class Event:
    t: float
    kind: EventKind
    name: str = ""
    command_id: int | None = None
    detail: str = ""
