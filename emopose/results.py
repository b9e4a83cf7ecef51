"""Writing a job's results: results.json for machines, results.md for people."""

from __future__ import annotations

import json
from pathlib import Path


def write_results(run_dir: Path, results: dict, markdown: str) -> None:
    run_dir.mkdir(parents=True, exist_ok=True)
    (run_dir / "results.json").write_text(json.dumps(results, indent=2, default=float) + "\n")
    (run_dir / "results.md").write_text(markdown.rstrip() + "\n")


def markdown_table(header: list[str], rows: list[list]) -> str:
    def cell(v):
        return f"{v:.2f}" if isinstance(v, float) else str(v)

    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(cell(v) for v in row) + " |" for row in rows]
    return "\n".join(lines)
