"""A Hydra callback that writes ONE comparison table for a whole sweep.

Registered in conf/config.yaml under hydra.callbacks. At the end of a multirun (any launcher: basic,
joblib, submitit, ray) it collects every job's results.json under the sweep directory and writes
sweep_results.json (the collected summaries) and sweep_results.md (the tables, ours beside the paper).
Rows are named by the job's own overrides (e.g. "planner=tfidf"), read from <job>/.hydra/overrides.yaml.
"""

from __future__ import annotations

import json
import logging
from pathlib import Path
from typing import Any

import yaml
from hydra.experimental.callback import Callback
from omegaconf import DictConfig

from emopose.bench.tables import TABLES, comparison_markdown

log = logging.getLogger(__name__)

SUMMARY_DROP = ("predictions",)  # per-item rows stay in each job's own results.json


def job_label(job_dir: Path, common: set[str]) -> str | None:
    overrides_file = job_dir / ".hydra" / "overrides.yaml"
    if not overrides_file.is_file():
        return None
    overrides = yaml.safe_load(overrides_file.read_text()) or []
    varying = [o for o in overrides if o not in common]
    return " ".join(varying) or None


def collect_results(root: Path) -> list[dict]:
    """Summaries of every benchmark results.json under root (sorted by path), labelled by job overrides."""
    def natural(path: Path) -> list[tuple[int, int | str]]:  # job 2 before job 10
        return [(0, int(part)) if part.isdigit() else (1, part) for part in path.relative_to(root).parts]

    paths = sorted(root.rglob("results.json"), key=natural)
    loaded = []
    for path in paths:
        try:
            result = json.loads(path.read_text())
        except (OSError, json.JSONDecodeError) as exc:
            log.warning("skipping unreadable %s: %s", path, exc)
            continue
        if isinstance(result, dict) and result.get("kind") in TABLES:
            loaded.append((path.parent, result))
    override_sets = []
    for job_dir, _ in loaded:
        f = job_dir / ".hydra" / "overrides.yaml"
        override_sets.append(set(yaml.safe_load(f.read_text()) or []) if f.is_file() else set())
    common = set.intersection(*override_sets) if override_sets else set()
    summaries = []
    for job_dir, result in loaded:
        summary = {k: v for k, v in result.items() if k not in SUMMARY_DROP}
        summary["job_dir"] = str(job_dir)
        summary["label"] = job_label(job_dir, common) or result.get("method")
        summaries.append(summary)
    return summaries


def write_sweep_table(root: str | Path, title: str = "Sweep results") -> Path | None:
    """Write sweep_results.{json,md} into root; returns the markdown path, or None if nothing was found."""
    root = Path(root)
    summaries = collect_results(root)
    if not summaries:
        log.info("no benchmark results.json under %s; no sweep table written", root)
        return None
    (root / "sweep_results.json").write_text(json.dumps(summaries, indent=2, default=float) + "\n")
    note = ("Cells: ours (paper), mean±SD over passes where passes > 1. "
            "Per-job details: each job_dir's results.md.")
    md = root / "sweep_results.md"
    md.write_text(f"# {title}\n\n{root}\n\n" + comparison_markdown(summaries, note))
    return md


class SweepTableCallback(Callback):
    """on_multirun_end: one comparison table over the sweep's jobs."""

    def on_multirun_end(self, config: DictConfig, **kwargs: Any) -> None:
        sweep_dir = Path(config.hydra.sweep.dir)
        md = write_sweep_table(sweep_dir)
        if md is not None:
            print(f"sweep table: {md}")
            print(md.read_text())
