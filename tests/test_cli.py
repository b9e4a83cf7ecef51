"""The README's commands, run as a user runs them: python -m emopose in a subprocess."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from emopose.config import PROJECT_ROOT


def run_cli(tmp_path, *args: str, timeout: float = 900) -> subprocess.CompletedProcess:
    env = {**os.environ, "HYDRA_FULL_ERROR": "1", "MUJOCO_GL": "egl", "HF_HUB_OFFLINE": "1"}
    return subprocess.run([sys.executable, "-m", "emopose", *args, f"hydra.run.dir={tmp_path}"],
                          cwd=PROJECT_ROOT, env=env, capture_output=True, text=True, timeout=timeout)


@pytest.mark.slow
def test_plan_experiment_prints_plan_resolution_releases_and_mcap(tmp_path):
    done = run_cli(tmp_path, "+experiment=plan", "planner=keyword", "utterance='Welcome! Look over there.'")
    assert done.returncode == 0, done.stderr[-2000:]
    assert "face_wave" in done.stdout and "point_forward_right" in done.stdout
    assert "session.mcap" in done.stdout
    results = json.loads((tmp_path / "results.json").read_text())
    assert [r["class"] for r in results["records"]] == ["welcoming", "pointing"]
    assert results["completed"] and (tmp_path / "session.mcap").stat().st_size > 0


@pytest.mark.slow
def test_main_job_runs_offline_with_the_default_planner(tmp_path):
    done = run_cli(tmp_path, "+experiment=bench_hard", "job.progress=false")
    assert done.returncode == 0, done.stderr[-2000:]
    results = json.loads((tmp_path / "results.json").read_text())
    assert results["method"] == "local" and results["n"] == 160
    assert results["accuracy"]["hard"]["mean"] > 40.0
    assert "hard" in done.stdout.lower()


def test_bad_override_is_a_clear_error_not_a_traceback(tmp_path):
    done = run_cli(tmp_path, "+experiment=plan", "planner=keyword", "pipeline.stages.schedule.mode=sideways",
                   timeout=120)
    assert done.returncode == 2
    assert "pipeline.stages.schedule" in done.stderr and "anchor" in done.stderr
    assert "Traceback" not in done.stderr


@pytest.mark.parametrize("overrides,named", [
    (["+experiment=plan", "planner=nope"], "planner=nope: no such option"),  # Hydra's own composition error
    (["+experiment=plan", "planner=keyword", "utterance=''"], "utterance is empty"),  # its owner refuses
])
def test_config_errors_are_one_line_on_stderr_and_exit_2(tmp_path, overrides, named):
    done = run_cli(tmp_path, *overrides, timeout=120)
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1 and done.stderr.startswith("error: ") and named in done.stderr, \
        done.stderr
