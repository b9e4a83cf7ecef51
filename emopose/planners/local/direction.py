"""Spatial words pick the pointing motion: "on your left" points left, "upstairs" points up.

A pointing act's trigger and its whole text are searched for a direction, strongest cue first: a side
(left, right), then up or down, behind, plain deixis (here, there, that, this), the listener (you), the
speaker (me, myself: "follow me" is rarer in a pointing act than "over there"). A side counts only where
the word names one ("on your left", "turn right", "the left-hand door"), not in "right there" or "I left
it". The direction's motion comes from planner.pointing_directions and must be a pointing motion of the
live library (else the chosen motion stays). It replaces only a motion the mapping names. A pointing
motion added by file points the way its description names ("point down: ... at the floor": down;
added_ways); the variant choice may give it only an act whose words name that way (off_way): its fit
to an act that names no direction comes from place words that merely sound alike ("main entrance" and
"the floor"), not from the way the act points. An added motion whose description names no direction is
chosen by its fit alone, and so kept.

Perspective (planner.pointing_frame): left and right name the robot's own sides. In the `shared` frame
(default) the robot shows the way standing beside its listener, both facing the place, so "your left",
"my left" and "the left" are one side (the suites' annotations read them so). In the `facing` frame the
robot faces its listener: the listener's sides ("your left", "on your right") are the robot's opposite
ones, while "my left" and a bare "the left" stay the robot's.
"""

from __future__ import annotations

import re
from typing import Literal

Frame = Literal["shared", "facing"]
_OWNER = r"(?:(?:to|on|at|toward|towards|from|by|off)\s+(?P<owner>the|your|my|our)\s+(?:far\s+)?)"
_SIDE = re.compile(rf"\b{_OWNER}(?P<side>left|right)\b(?!\s*,?\s*(?:now|away|then)\b)"
                   r"|\b(?P<verb>turn|go|keep|bear|head|veer|swing|look)\s+(?P<side2>left|right)\b"
                   r"|\b(?P<side3>left|right)(?:-hand|\s+side|\s+of|\s+wing|\s+corner|\s+door|\s+aisle)\b",
                   re.IGNORECASE)
_CUES = (
    ("up", re.compile(r"\b(?:up(?!\s+(?:ahead|front|until|the\s+(?:road|street|corridor|hall)))|upstairs|"
                      r"above|overhead|ceiling|sky|top\s+floor|rafters|roof)\b", re.I)),
    ("down", re.compile(r"\b(?:down|downstairs|below|beneath|underneath|floor|basement|ground)\b", re.I)),
    ("behind", re.compile(r"\b(?:behind|back\s+there|at\s+the\s+back|rear)\b", re.I)),
    ("here", re.compile(r"\bhere\b", re.I)),
    ("there", re.compile(r"\b(?:there|that|those|yonder)\b", re.I)),
    ("this", re.compile(r"\b(?:this|these)\b", re.I)),
    ("you", re.compile(r"\b(?:you|yourself|your)\b", re.I)),
    ("me", re.compile(r"\b(?:me|myself|my\s+own)\b", re.I)),
)
_MIRROR = {"left": "right", "right": "left"}


def _ranked(text: str, frame: Frame) -> tuple[int, str] | None:
    """(strength rank, direction) of the strongest cue in the text (0: a side), or None."""
    side = _SIDE.search(text)
    if side is not None:
        name = (side.group("side") or side.group("side2") or side.group("side3")).lower()
        listener = (side.group("owner") or "").lower() == "your"
        return 0, _MIRROR[name] if frame == "facing" and listener else name
    return next(((rank, name) for rank, (name, cue) in enumerate(_CUES, 1) if cue.search(text)), None)


def direction_of(text: str, frame: Frame = "shared") -> str | None:
    """The strongest direction the text names, in the robot's frame (module docstring), or None."""
    ranked = _ranked(text, frame)
    return None if ranked is None else ranked[1]


def pointing_motion(texts: tuple[str, ...], motions: dict[str, str], pointing: frozenset[str],
                    frame: Frame = "shared") -> str | None:
    """The motion for the strongest direction the texts name (the trigger, then the act: a trigger cut
    short of "on the left" still points left; equal cues, the earlier text), mapped to a pointing motion
    of the library (motions: direction -> name; pointing: the library's pointing motions), or None."""
    found = [(ranked, k) for k, text in enumerate(texts) if (ranked := _ranked(text, frame)) is not None]
    if not found:
        return None
    motion = motions.get(min(found)[0][1])
    return motion if motion in pointing else None


def added_ways(evidence: dict[str, tuple[str, tuple[str, ...]]], motions: dict[str, str],
               frame: Frame = "shared") -> dict[str, str]:
    """Pointing motions outside the mapping (added by file) -> the way their description names (those
    naming none left out). evidence: name -> (class, (description text, *examples)), the live library's;
    motions: direction -> name, the mapping."""
    mapped = set(motions.values())
    ways = {name: direction_of(texts[0], frame) for name, (cls, texts) in evidence.items()
            if cls == "pointing" and name not in mapped}
    return {name: way for name, way in ways.items() if way is not None}


def off_way(text: str, ways: dict[str, str], frame: Frame = "shared") -> frozenset[str]:
    """The added pointing motions (ways: added_ways()) that point a way the act's text does not name."""
    named = direction_of(text, frame)
    return frozenset(name for name, way in ways.items() if way != named)
