"""The class-variant guide: the live library, written out for a language model.

The guide is regenerated from the library's current snapshot, so a motion saved in Pose Studio is
offered to the model on the next request without rebuilding the planner (paper, "System Boundary":
"the same library regenerates its current class-variant guide"). Text is cached per library
version because a benchmark renders it hundreds of times per second. Two forms: the full guide (one
line per motion with its description) and the short one for small models (one line per class, names
only, the class default first).
"""

from __future__ import annotations

import threading
import weakref

from emopose import CLASSES
from emopose.library import LibrarySnapshot, MotionLibrary

# (id(library), form) -> (weak reference to that library, version, guide text). The weak reference guards
# against a recycled id after a library is garbage-collected; MotionLibrary is an unhashable dataclass.
_CACHE: dict[tuple[int, str], tuple[weakref.ref, int, str]] = {}
_LOCK = threading.Lock()


def render_guide(snapshot: LibrarySnapshot) -> str:
    """Build the guide text for one library snapshot (uncached)."""
    lines = []
    for cls in CLASSES:
        entries = snapshot.by_class(cls)
        default = snapshot.class_defaults.get(cls)
        if not entries:
            lines.append(f"{cls}: no motions loaded (a record of this class is performed as neutral)")
            continue
        lines.append(f"{cls}:")
        for entry in entries:
            mark = " (class default)" if entry.name == default else ""
            lines.append(f"  - {entry.name}{mark}: {entry.description}")
    return "\n".join(lines)


def render_short_guide(snapshot: LibrarySnapshot) -> str:
    """One line per class: its motion names, the class default first (uncached)."""
    lines = []
    for cls in CLASSES:
        names = [e.name for e in snapshot.by_class(cls)]
        default = snapshot.class_defaults.get(cls)
        names.sort(key=lambda name: name != default)  # stable: the default first, the rest in library order
        lines.append(f"{cls}: {', '.join(names) if names else '(none: performed as neutral)'}")
    return "\n".join(lines)


FORMS = {"full": render_guide, "short": render_short_guide}


def library_guide(library: MotionLibrary, form: str = "full") -> str:
    """The guide for the library's current version; classes in CLASSES order, defaults marked (full) or
    first (short)."""
    snapshot = library.snapshot  # one snapshot, so the text and its version cannot disagree
    version, key = snapshot.version, (id(library), form)
    with _LOCK:
        cached = _CACHE.get(key)
        if cached is not None and cached[0]() is library and cached[1] == version:
            return cached[2]
    text = FORMS[form](snapshot)
    with _LOCK:
        _CACHE[key] = (weakref.ref(library), version, text)
    return text
