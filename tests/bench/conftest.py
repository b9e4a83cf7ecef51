"""Fixtures for the benchmark tests: small suite files and composing + running an experiment."""

from __future__ import annotations

from pathlib import Path

import pytest

from emopose.app import run

FIXTURES = Path(__file__).parent / "fixtures"


@pytest.fixture(scope="session")
def library_overrides(library) -> list[str]:
    """Point the config at the shared synthetic test library (tests/conftest.py) instead of library/g1."""
    folder = library.paths[0]
    return [f"library.paths=[{folder}]", f"library.limits={folder / 'limits.yaml'}", "library.write_dir=null",
            "library.class_defaults=null", "run.record=false"]


@pytest.fixture
def run_experiment(library_overrides, tmp_path, compose):
    """run_experiment("bench_all", "bench.path=...", ...) -> (results dict, run_dir)."""

    def _run(experiment: str, *overrides: str, planner: str = "keyword"):
        cfg = compose(f"+experiment={experiment}", f"planner={planner}", "job.progress=false",
                      *library_overrides, *overrides)
        run_dir = tmp_path / experiment
        return run(cfg, run_dir), run_dir

    return _run
