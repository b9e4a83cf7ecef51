"""What the local planner reads of the live library's motions: their class and the texts that describe
their uses (the description, and the optional `examples:` utterances of a motion file)."""

from __future__ import annotations

from emopose.library import MotionLibrary


def motion_catalogue(library: MotionLibrary) -> dict[str, tuple[str, str]]:
    """Selectable motions of the live library: name -> (class, text its description is matched by)."""
    return {e.name: (e.cls, f"{e.name.replace('_', ' ')}: {e.description}")
            for e in library.snapshot.entries.values() if e.motion_type == "sequence"}


def motion_evidence(library: MotionLibrary) -> dict[str, tuple[str, tuple[str, ...]]]:
    """name -> (class, (description text, *example utterances)): what the variant choice compares an act
    with (planners/local/variants.py). Examples are read as they are, without retraining."""
    entries = library.snapshot.entries
    return {name: (cls, (text, *entries[name].examples))
            for name, (cls, text) in motion_catalogue(library).items()}
