"""The robot-owned motion library: motion files, class defaults and the planner's guide.

A library set is a folder of YAML files, one motion per file (see library/README.md). Loading
validates every file once and names the file, the entry and the field in any error. The library is
live: `reload()` and `save()` swap in a new immutable snapshot under a lock, and bump `version`,
so planners regenerate their guide and the resolver sees new variants without a restart.
"""

from __future__ import annotations

import logging
import os
import shutil
import tempfile
import threading
from dataclasses import dataclass, field
from pathlib import Path

import yaml
from pydantic import ValidationError

from emopose import CLASSES
from emopose.contract import MAX_KEYFRAMES, LibraryEntry
from emopose.joint_limits import JointLimits, LibraryError
from emopose.robot.g1_spec import NUM_JOINTS

log = logging.getLogger(__name__)

# The largest motion file read: the longest sequence the schema allows (14 keyframes of 14 values), written
# one full-precision value a line, is under 5 KB; 64 KiB leaves room for comments.
MAX_FILE_BYTES = 64 * 1024
MAX_PROBLEMS = 3  # a file's first problems named in its one-line error; the rest counted


@dataclass(frozen=True)
class LibrarySnapshot:
    """An immutable view of the library at one version."""

    version: int
    entries: dict[str, LibraryEntry]
    files: dict[str, Path]
    class_defaults: dict[str, str]
    neutral: str

    def by_class(self, cls: str) -> list[LibraryEntry]:
        return [e for e in self.entries.values() if e.cls == cls and e.name != self.neutral]


@dataclass
class MotionLibrary:
    """Loads library folders, validates them against the joint limits and serves live snapshots.

    `class_defaults` maps a class to its first configured primitive (the resolver's l_c^(0)); a class
    without an entry there defaults to its first motion in file-name order. `neutral` names l_neutral.
    `write_dir` is where new or edited motions are saved (Pose Studio); it is one of `paths`.
    """

    paths: list[Path]
    limits: JointLimits
    class_defaults: dict[str, str] = field(default_factory=dict)
    neutral: str = "neutral_rest"
    write_dir: Path | None = None
    limit_margin: float = 0.0
    _lock: threading.Lock = field(default_factory=threading.Lock, repr=False)
    _snapshot: LibrarySnapshot | None = field(default=None, repr=False)

    @classmethod
    def from_config(
        cls,
        paths: list[str],
        limits: str,
        class_defaults: dict[str, str] | None = None,
        neutral: str = "neutral_rest",
        write_dir: str | None = None,
        limit_margin: float = 0.0,
    ) -> MotionLibrary:
        library = cls(
            paths=[Path(p) for p in paths],
            limits=JointLimits.from_file(limits),
            class_defaults=dict(class_defaults or {}),
            neutral=neutral,
            write_dir=Path(write_dir) if write_dir else None,
            limit_margin=limit_margin,
        )
        library.reload()
        return library

    # -- reading -------------------------------------------------------------------------------
    @property
    def snapshot(self) -> LibrarySnapshot:
        assert self._snapshot is not None, "call reload() first"
        return self._snapshot

    @property
    def version(self) -> int:
        return self.snapshot.version

    def get(self, name: str) -> LibraryEntry | None:
        return self.snapshot.entries.get(name)

    @property
    def names(self) -> list[str]:
        return list(self.snapshot.entries)

    def by_class(self, cls: str) -> list[LibraryEntry]:
        return self.snapshot.by_class(cls)

    def class_default(self, cls: str) -> LibraryEntry | None:
        snap = self.snapshot
        name = snap.class_defaults.get(cls)
        return snap.entries[name] if name else None

    @property
    def neutral_entry(self) -> LibraryEntry:
        return self.snapshot.entries[self.snapshot.neutral]

    # -- loading -------------------------------------------------------------------------------
    def reload(self) -> LibrarySnapshot:
        entries: dict[str, LibraryEntry] = {}
        files: dict[str, Path] = {}
        for folder in self.paths:
            if not folder.is_dir():
                raise LibraryError(f"library folder {folder} does not exist (set library.paths)")
            for path in sorted(folder.glob("*.yaml")):
                if path.name == "limits.yaml":
                    continue
                entry = self._load_file(path)
                if entry.name in entries:
                    raise LibraryError(f"{path}: motion name '{entry.name}' is already defined in "
                                       f"{files[entry.name]}")
                entries[entry.name] = entry
                files[entry.name] = path
        with self._lock:
            version = self._snapshot.version + 1 if self._snapshot else 1
            self._snapshot = self._make_snapshot(version, entries, files)
        return self._snapshot

    def _load_file(self, path: Path) -> LibraryEntry:
        try:
            size = path.stat().st_size
            if size > MAX_FILE_BYTES:  # refused before parsing: pure-Python YAML takes minutes on megabytes
                raise LibraryError(f"{path}: {size} bytes; a motion file is at most {MAX_FILE_BYTES} bytes "
                                   f"({MAX_KEYFRAMES} keyframes of {NUM_JOINTS} values)")
            raw = yaml.safe_load(path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, yaml.YAMLError) as exc:  # binary data is not UTF-8 YAML
            raise LibraryError(f"{path}: not readable YAML ({' '.join(str(exc).split())})") from exc
        entry = self.validate(raw, source=str(path))
        if entry.stroke is None and entry.motion_type == "sequence":
            log.warning("%s: no `stroke: [start, end]`; "
                        "using the largest-excursion keyframe %s as the stroke",
                        path, list(entry.stroke_span))
        return entry

    def validate(self, raw: object, source: str) -> LibraryEntry:
        """Validate one motion (a mapping as in a library file) against the schema and the joint limits."""
        if not isinstance(raw, dict):
            raise LibraryError(f"{source}: expected a mapping with name, class, description, keyframes")
        try:  # strict: `duration: "2"` or `stroke: [1.0, 2]` is refused, not coerced
            entry = LibraryEntry.model_validate(_lists_as_tuples(raw), strict=True)
        except ValidationError as exc:
            problems = [_problem(error) for error in exc.errors()]
            more = f"; and {len(problems) - MAX_PROBLEMS} more" if len(problems) > MAX_PROBLEMS else ""
            raise LibraryError(f"{source}: motion '{raw.get('name', '?')}': "
                               f"{'; '.join(problems[:MAX_PROBLEMS])}{more}") from exc
        bad = self.limits.violation_details(entry.q, self.limit_margin)
        if bad:
            raise LibraryError(
                f"{source}: motion '{entry.name}': keyframes leave the joint limits "
                f"(kept {self.limit_margin} rad "
                f"inside the limits file's range): {'; '.join(bad)}"
            )
        return entry

    def _make_snapshot(self, version: int, entries: dict[str, LibraryEntry],
                       files: dict[str, Path]) -> LibrarySnapshot:
        if self.neutral not in entries:
            raise LibraryError(f"neutral motion '{self.neutral}' is not in the library "
                               f"{[str(p) for p in self.paths]}")
        defaults: dict[str, str] = {}
        for cls in CLASSES:
            configured = self.class_defaults.get(cls)
            if configured is not None:
                entry = entries.get(configured)
                if entry is None or entry.cls != cls:
                    raise LibraryError(
                        f"library.class_defaults.{cls} = '{configured}' is not a loaded motion of class {cls}"
                    )
                defaults[cls] = configured
            else:
                members = [n for n, e in entries.items() if e.cls == cls and n != self.neutral]
                if members:
                    defaults[cls] = members[0]
        unknown = set(self.class_defaults) - set(CLASSES)
        if unknown:
            raise LibraryError(f"library.class_defaults has unknown classes {sorted(unknown)}; "
                               f"allowed: {CLASSES}")
        return LibrarySnapshot(version, entries, files, defaults, self.neutral)

    # -- writing (Pose Studio) -----------------------------------------------------------------
    def save(self, raw: dict) -> LibraryEntry:
        """Validate and atomically write one motion into `write_dir`, keeping a backup of a replaced file."""
        if self.write_dir is None:
            raise LibraryError("this library has no write_dir configured; set library.write_dir")
        entry = self.validate(raw, source="saved motion")
        existing = self.snapshot.files.get(entry.name)
        target = existing if existing is not None else self.write_dir / f"{entry.name}.yaml"
        if target.resolve().parent not in {p.resolve() for p in self.paths}:
            raise LibraryError(f"refusing to write {target}: outside the library folders")
        text = yaml.safe_dump(entry.model_dump(mode="json", by_alias=True, exclude_none=True),
                              sort_keys=False)
        target.parent.mkdir(parents=True, exist_ok=True)
        if target.exists():
            backups = target.parent / ".backup"
            backups.mkdir(exist_ok=True)
            shutil.copy2(target, backups / f"{target.stem}.v{self.version}.yaml")
        fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{entry.name}.", suffix=".tmp")
        with os.fdopen(fd, "w") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, target)
        self.reload()
        return entry


def _lists_as_tuples(value: object) -> object:
    """A parsed file's lists as tuples: in strict mode the contract's tuple fields take tuples only."""
    if isinstance(value, list):
        return tuple(_lists_as_tuples(v) for v in value)
    if isinstance(value, dict):
        return {key: _lists_as_tuples(v) for key, v in value.items()}
    return value


def _problem(error: dict) -> str:
    """One validation error as `field: rule`, with the value given when its type was wrong."""
    where = ".".join(map(str, error["loc"])) or "entry"
    given = error.get("input")
    if error["type"].endswith("_type"):  # the wrong type: say which value, briefly
        return f"{where}: {error['msg']}, got {type(given).__name__} {repr(given)[:40]}"
    return f"{where}: {error['msg']}"
