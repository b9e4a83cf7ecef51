"""One table per sweep (the Hydra callback) and the results/ report, on small fixtures."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from emopose.bench.sweep_callback import collect_results, write_sweep_table
from emopose.config import PROJECT_ROOT
from emopose.report import build_report

FIXTURES = Path(__file__).parent / "fixtures"


def fake_job(root: Path, num: int, method: str, overall: float, overrides: list[str]) -> None:
    job = root / str(num)
    (job / ".hydra").mkdir(parents=True)
    (job / ".hydra" / "overrides.yaml").write_text(yaml.safe_dump(overrides))
    acc = {"easy": {"mean": overall, "sd": None}, "medium": None, "hard": None,
           "overall": {"mean": overall, "sd": None}}
    (job / "results.json").write_text(json.dumps({"kind": "bench", "suite": "s.jsonl", "method": method,
                                                  "n": 8, "passes": 1, "accuracy": acc,
                                                  "predictions": [{"id": "x"}]}))


def test_callback_table_collects_every_job_in_job_order(tmp_path):
    for num in range(11):
        fake_job(tmp_path, num, f"m{num}", float(num), ["+experiment=bench_easy", f"planner=m{num}"])
    (tmp_path / "notes").mkdir()
    (tmp_path / "notes" / "results.json").write_text("[1, 2]")  # not a benchmark result: ignored
    summaries = collect_results(tmp_path)
    assert [s["label"] for s in summaries] == [f"planner=m{n}" for n in range(11)]
    assert all("predictions" not in s for s in summaries)
    md = write_sweep_table(tmp_path).read_text()
    assert "| planner=m10 | 8 | 1 | 10.00 |" in md
    assert json.loads((tmp_path / "sweep_results.json").read_text())[2]["method"] == "m2"


def test_no_results_no_table(tmp_path):
    assert write_sweep_table(tmp_path) is None


def test_report_writes_results_tables(tmp_path, library_overrides):
    overrides = [f"bench.path={FIXTURES / 'bench_small.jsonl'}", "job.progress=false", *library_overrides]
    md = build_report(tmp_path, ["keyword", "chance"], ["bench_all"], overrides).read_text()
    assert "| keyword | 24 | 1 |" in md and "| chance | 24 | 1 |" in md and "(62.50)" in md
    saved = json.loads((tmp_path / "results.json").read_text())
    assert [s["method"] for s in saved] == ["keyword", "chance"]
    assert (tmp_path / "runs" / "bench_all" / "keyword" / "confusion.png").is_file()


def test_report_names_a_missing_suite(tmp_path, library_overrides):
    overrides = [f"bench.path={tmp_path / 'absent.jsonl'}", *library_overrides]
    md = build_report(tmp_path, ["keyword"], ["context_ablation"], overrides).read_text()
    assert "absent.jsonl is missing; not run" in md


@pytest.mark.slow
def test_cli_sweep_writes_one_table(tmp_path, library_overrides):
    """The README's sweep command, on the fixture suite, with the joblib launcher."""
    sweep_dir = tmp_path / "sweep"
    cmd = [sys.executable, "-m", "emopose", "-m", "+experiment=bench_all",
           "planner=keyword,tfidf,jaccard,chance", f"bench.path={FIXTURES / 'bench_small.jsonl'}",
           f"hydra.sweep.dir={sweep_dir}",
           "hydra/launcher=joblib", "hydra.launcher.n_jobs=2", *library_overrides]
    done = subprocess.run(cmd, check=False, cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=300,
                          env={**os.environ, "HYDRA_FULL_ERROR": "1"})
    assert done.returncode == 0, done.stderr[-3000:]
    md = (sweep_dir / "sweep_results.md").read_text()
    for planner in ("keyword", "tfidf", "jaccard", "chance"):
        assert f"| planner={planner} | 24 | 1 |" in md
    assert len(json.loads((sweep_dir / "sweep_results.json").read_text())) == 4
