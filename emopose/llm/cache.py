"""On-disk response cache for LLM calls: one small JSON file per request, keyed by a sha256.

One file per key (not one SQLite database) because Hydra sweeps run benchmark jobs in parallel
processes: atomic `os.replace` writes need no locking, and a corrupt or half-written file is just
a miss. The key covers everything that can change the answer (model, endpoint, messages, sampling
parameters, pass index) and nothing that cannot (timeouts, retry counts).
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import tempfile
import time
from pathlib import Path

log = logging.getLogger(__name__)


def cache_key(payload: dict) -> str:
    """sha256 of the canonical JSON of `payload` (sorted keys, so dict order never matters)."""
    canonical = json.dumps(payload, sort_keys=True, ensure_ascii=False, separators=(",", ":"), default=str)
    return hashlib.sha256(canonical.encode("utf-8")).hexdigest()


class ResponseCache:
    """get/put answer text by key under `directory` (created on first write)."""

    def __init__(self, directory: str | Path) -> None:
        self.directory = Path(directory).expanduser()

    def _path(self, key: str) -> Path:
        return self.directory / key[:2] / f"{key}.json"  # fan out so no folder holds 100k files

    def get(self, key: str) -> str | None:
        try:
            entry = json.loads(self._path(key).read_text(encoding="utf-8"))
        except (OSError, json.JSONDecodeError):
            return None
        text = entry.get("text") if isinstance(entry, dict) else None
        return text if isinstance(text, str) else None

    def put(self, key: str, text: str, meta: dict | None = None) -> None:
        """Write atomically. A failure to cache is never a failure to plan, but it is logged (a full disk
        or a read-only cache folder otherwise shows only as runs that never get faster)."""
        path, tmp = self._path(key), None
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".tmp-", suffix=".json")
            with os.fdopen(fd, "w", encoding="utf-8") as f:
                json.dump({"text": text, "created": time.time(), **(meta or {})}, f, ensure_ascii=False)
            os.replace(tmp, path)
        except OSError as exc:
            log.warning("LLM cache: could not write %s (%s); the answer is used uncached", path, exc)
            if tmp is not None:
                Path(tmp).unlink(missing_ok=True)
