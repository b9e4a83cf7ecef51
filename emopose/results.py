"""Writing a job's results: results.json for machines, results.md for people.

A job returns `(results, markdown)` (JobOutput); the entry point (emopose/app.py) writes them with
write_results and prints the markdown, so every job ends the same way. A job that ran to its end but
must fail (a fault on the robot, a planner that fell back too often) raises JobFailure instead: its
results are written and printed all the same, then its error decides the exit status.
"""

from __future__ import annotations

import json
from pathlib import Path

JobOutput = tuple[dict, str]  # (results for results.json, markdown for results.md and the terminal)


class JobFailure(Exception):
    """A finished job that failed: `results` and `markdown` are written, then `error` is raised."""

    def __init__(self, results: dict, markdown: str, error: BaseException) -> None:
        super().__init__(str(error))
        self.results, self.markdown, self.error = results, markdown, error


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
