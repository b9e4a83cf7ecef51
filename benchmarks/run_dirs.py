"""Shared by the served benchmarks: measure in --run-dir (kept) or a temporary folder; print JSON."""

from __future__ import annotations

import json
import tempfile
from pathlib import Path


def measure_and_print(measure, args, prefix: str) -> None:
    if args.run_dir is not None:
        args.run_dir.mkdir(parents=True, exist_ok=True)
        print(json.dumps(measure(args, args.run_dir), indent=2))
        return
    with tempfile.TemporaryDirectory(prefix=prefix) as folder:
        print(json.dumps(measure(args, Path(folder)), indent=2))
