"""python -m emopose.report: regenerate results/ (every baseline on the three suites).

Runs each experiment (bench_all, context_ablation, sequence_suite) for each planner through the same
Hydra composition and jobs as the CLI, one run directory per pair under <out>/runs/<experiment>/<planner>,
then writes <out>/results.md and <out>/results.json: the comparison tables, ours beside the paper.
A suite whose data file is missing is skipped and named in the report.

  python -m emopose.report                                   # the five local baselines
  python -m emopose.report --planners keyword tfidf --out /tmp/results
  python -m emopose.report --override passes=5 --override planner.seed=1
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import time
from pathlib import Path

from hydra import compose, initialize_config_dir
from omegaconf import OmegaConf

from emopose.app import run
from emopose.bench.sweep_callback import collect_results
from emopose.bench.tables import comparison_markdown
from emopose.config import CONFIG_DIR, PROJECT_ROOT

BASELINES = ("local", "keyword", "tfidf", "jaccard", "sbert_centroids", "chance")
EXPERIMENTS = ("bench_all", "context_ablation", "sequence_suite")


class MissingSuite(Exception):
    """The experiment's suite file (bench.path) does not exist yet."""


def run_one(experiment: str, planner: str, run_dir: Path, overrides: list[str]) -> float:
    """Compose +experiment=<experiment> planner=<planner> (+ overrides), run it into run_dir; wall seconds."""
    with initialize_config_dir(config_dir=str(CONFIG_DIR), version_base="1.3"):
        cfg = compose("config", overrides=[f"+experiment={experiment}", f"planner={planner}",
                                           "run.record=false",
                                           *overrides])
    suite = Path(OmegaConf.select(cfg, "bench.path"))
    if not suite.is_file():
        raise MissingSuite(suite)
    if run_dir.exists():
        shutil.rmtree(run_dir)
    started = time.perf_counter()
    run(cfg, run_dir)
    elapsed = time.perf_counter() - started
    portable_paths(run_dir)
    return elapsed


def portable_paths(run_dir: Path) -> None:
    """Make checkout paths in a run's results relative, so results/ reads the same on every machine."""
    prefix = f"{PROJECT_ROOT}/"
    for name in ("results.json", "results.md"):
        path = run_dir / name
        if path.is_file():
            path.write_text(path.read_text().replace(prefix, ""))


def build_report(out: Path, planners: list[str], experiments: list[str], overrides: list[str]) -> Path:
    notes, walls = [], []
    for experiment in experiments:
        for planner in planners:
            run_dir = out / "runs" / experiment / planner
            print(f"== {experiment} / {planner}", file=sys.stderr)
            try:
                walls.append((experiment, planner, run_one(experiment, planner, run_dir, overrides)))
            except MissingSuite as exc:
                notes.append(f"- {experiment}: suite file {exc.args[0]} is missing; not run.")
                break
    order = {(e, p): k for k, (e, p) in enumerate((e, p) for e in experiments for p in planners)}
    summaries = sorted(collect_results(out / "runs"),
                       key=lambda s: order.get(Path(s["job_dir"]).parts[-2:], len(order)))
    for s in summaries:
        s["label"] = s["method"]
        s["job_dir"] = str(Path(s["job_dir"]).relative_to(out))
        s["suite"] = _relative(s["suite"])
    (out / "results.json").write_text(json.dumps(summaries, indent=2, default=float) + "\n")
    timing = "\n".join(f"- {e} / {p}: {w:.1f} s" for e, p, w in walls)
    body = comparison_markdown(summaries)
    text = (
        "# EmoPose baselines: results\n\n"
        "Regenerate with `python -m emopose.report` (see docs/benchmarks.md). Cells are "
        "\"ours (paper)\"; the paper reports baselines only on EmoPose-Bench, and the context and sequence "
        "suites only for its GPT-5.5 planner (shown as paper-only reference rows). Deterministic planners "
        "run one pass. Per-run details, predictions and confusion matrices: runs/<experiment>/<planner>/.\n\n"
        f"{body}\n"
        + ("## Not run\n\n" + "\n".join(notes) + "\n\n" if notes else "")
        + f"## Wall time per run\n\n{timing}\n"
    )
    md = out / "results.md"
    md.write_text(text)
    return md


def _relative(path: str) -> str:
    try:
        return str(Path(path).resolve().relative_to(PROJECT_ROOT))
    except ValueError:
        return path


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, default=PROJECT_ROOT / "results", help="output folder")
    parser.add_argument("--planners", nargs="+", default=list(BASELINES))
    parser.add_argument("--experiments", nargs="+", default=list(EXPERIMENTS))
    parser.add_argument("--override", action="append", default=[], metavar="KEY=VALUE",
                        help="extra Hydra override for every run (repeatable)")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    md = build_report(args.out, args.planners, args.experiments, args.override)
    print(md.read_text())
    print(f"wrote {md} in {time.perf_counter() - started:.1f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
