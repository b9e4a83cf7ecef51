"""`python -m emopose` reaches its stop-signal handler before any import it can postpone: the window in
which a SIGTERM exits 143 unhandled is the interpreter's start alone (emopose/__main__.py)."""

from __future__ import annotations

import subprocess
import sys

POSTPONED = {"json", "logging", "numpy", "hydra", "omegaconf", "emopose.app"}
PROBE = "import sys; before = set(sys.modules); import emopose.__main__; print(*set(sys.modules) - before)"


def test_nothing_postponable_is_imported_before_the_handler():
    loaded = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True, check=True)
    imported = set(loaded.stdout.split())
    assert "emopose.stop_signals" in imported
    assert not imported & POSTPONED, sorted(imported & POSTPONED)  # before: json and logging (~25 ms)
