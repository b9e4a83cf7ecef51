"""Saving a Pose Studio motion into the live library.

MotionLibrary.save validates, writes atomically, keeps a backup of a replaced file and reloads (so
the resolver and every planner's guide see the motion at once). This adds the checks that belong at
the request edge: the name pattern, an explicit overwrite, the target folder, and the studio's own
verdict (limits and self-collision at the nominal intensity) so an unusable motion is never stored.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from emopose.contract import LibraryEntry
from emopose.joint_limits import LibraryError
from emopose.library import MotionLibrary
from emopose.studio.authoring import PoseStudio

NAME_PATTERN = r"^[a-z][a-z0-9_]{1,63}$"


def valid_name(name: object) -> bool:
    """Motion names double as file names: the strict pattern rules out traversal and odd characters."""
    return isinstance(name, str) and re.fullmatch(NAME_PATTERN, name) is not None


class SaveRefused(ValueError):
    """The motion is not saved; `status` is the HTTP status that says why (409 exists, 422 invalid)."""

    def __init__(self, message: str, status: int = 422) -> None:
        super().__init__(message)
        self.status = status


@dataclass(frozen=True)
class SaveResult:
    entry: LibraryEntry
    file: Path
    backup: Path | None
    version: int
    replaced: bool


def target_path(library: MotionLibrary, name: str) -> Path:
    """Where `name` would be written; refuses anything that does not resolve into a library folder."""
    if not valid_name(name):
        raise SaveRefused(f"motion name {name!r} must match ^[a-z][a-z0-9_]{{1,63}}$ "
                          "(lower case, digits, underscores; starts with a letter)")
    if library.write_dir is None:
        raise SaveRefused("this library is read-only: set library.write_dir to save motions", 409)
    existing = library.snapshot.files.get(name)
    target = existing if existing is not None else library.write_dir / f"{name}.yaml"
    folders = {p.resolve() for p in library.paths}
    if target.resolve().parent not in folders:
        raise SaveRefused(f"refusing to write {name}: it would land outside the library folders", 403)
    return target


def save_motion(studio: PoseStudio, raw: dict, overwrite: bool = False) -> SaveResult:
    library = studio.library
    name = raw.get("name")
    target = target_path(library, name)
    replaced = library.get(name) is not None
    if replaced and not overwrite:
        raise SaveRefused(f"a motion named {name!r} exists; save with overwrite to replace it "
                          "(the old file is kept in .backup/)", 409)
    if replaced and name == library.neutral and raw.get("class") != "neutral":
        raise SaveRefused(f"{name!r} is the neutral rest pose; it must stay class neutral")
    try:
        entry = library.validate(raw, source="Pose Studio")
    except LibraryError as exc:
        raise SaveRefused(str(exc)) from exc
    problems = studio.report(entry).problems
    if problems:
        raise SaveRefused(f"motion {name!r} not saved: " + "; ".join(problems))
    backup = target.parent / ".backup" / f"{target.stem}.v{library.version}.yaml" if target.exists() else None
    try:
        saved = library.save(raw)
    except LibraryError as exc:
        raise SaveRefused(str(exc)) from exc
    return SaveResult(saved, target, backup if backup and backup.exists() else None, library.version,
                      replaced)


def _removable(library: MotionLibrary, name: str) -> Path:
    """The file of a motion that may be deleted or renamed: it exists in a writable library folder, is not
    the neutral rest pose nor a configured class default, and is not the last motion of its class (the
    resolver needs one per class)."""
    path = target_path(library, name)
    entry = library.get(name)
    if entry is None:
        raise SaveRefused(f"no motion named {name!r}", 404)
    if name == library.neutral:
        raise SaveRefused(f"{name!r} is the neutral rest pose; every gesture starts and ends there", 409)
    if name in library.class_defaults.values():
        raise SaveRefused(f"{name!r} is a configured class default (library.class_defaults)", 409)
    if len(library.snapshot.by_class(entry.cls)) <= 1:
        raise SaveRefused(f"{name!r} is the only {entry.cls} motion; the resolver needs one per class", 409)
    return path


def _retire(library: MotionLibrary, path: Path) -> Path:
    """Move a motion's file into .backup/ (as a save keeps a replaced file) and reload the library."""
    backup = path.parent / ".backup" / f"{path.stem}.v{library.version}.removed.yaml"
    backup.parent.mkdir(exist_ok=True)
    path.replace(backup)
    try:
        library.reload()
    except LibraryError:
        backup.replace(path)  # the library must stay loadable: put the file back
        library.reload()
        raise
    return backup


def delete_motion(library: MotionLibrary, name: str) -> Path:
    """Remove a motion from the live library; its file is kept in .backup/. Returns the backup."""
    path = _removable(library, name)
    try:
        return _retire(library, path)
    except LibraryError as exc:
        raise SaveRefused(f"{name!r} not deleted: {exc}", 409) from exc


def rename_motion(studio: PoseStudio, name: str, new_name: str) -> SaveResult:
    """Save the motion under new_name (every save check) and retire the old file into .backup/."""
    library = studio.library
    path = _removable(library, name)
    raw = library.get(name).model_dump(mode="json", by_alias=True, exclude_none=True) | {"name": new_name}
    saved = save_motion(studio, raw)  # refuses an existing or malformed new name
    backup = _retire(library, path)
    return SaveResult(saved.entry, saved.file, backup, library.version, replaced=False)
