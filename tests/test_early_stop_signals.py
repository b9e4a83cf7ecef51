"""SIGTERM in the first seconds of `python -m emopose` (imports, Hydra composition, the run directory just
chosen, the job being built): exit 143, and results.json saying so wherever the run directory is known,
else one line on stderr saying that no results were written. A real process, sent a real SIGTERM once it
has reached each moment (tests/paused_start.py pauses it there)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import pytest

from emopose.config import PROJECT_ROOT
from tests.paused_start import MOMENTS, PAUSED


def sigterm_at(moment: str, run_dir, marker) -> subprocess.CompletedProcess:
    env = {**os.environ, "MUJOCO_GL": "egl", "HF_HUB_OFFLINE": "1", PAUSED: str(marker)}
    command = [sys.executable, "-m", "tests.paused_start", moment, "+experiment=plan", "planner=keyword",
               "utterance=Hello", f"hydra.run.dir={run_dir}"]
    job = subprocess.Popen(command, cwd=PROJECT_ROOT, env=env, stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True)
    try:
        while not marker.exists() and job.poll() is None:
            time.sleep(0.02)
        job.send_signal(signal.SIGTERM)
        stdout, stderr = job.communicate(timeout=120)
    finally:
        job.kill()
    return subprocess.CompletedProcess(command, job.returncode, stdout, stderr)


@pytest.mark.parametrize("moment", MOMENTS)
def test_sigterm_at_the_start_exits_143_with_results_wherever_the_run_directory_is_known(moment, tmp_path):
    run_dir, marker = tmp_path / "run", tmp_path / "paused.txt"
    run_dir.mkdir()
    (run_dir / "results.json").write_text('{"completed": true}')  # an earlier run's, in a reused directory
    done = sigterm_at(moment, run_dir, marker)
    assert marker.read_text() == moment  # the signal came at that moment, not before or after it
    assert done.returncode == 143, done.stderr[-3000:]
    assert "Traceback" not in done.stderr, done.stderr[-3000:]
    results = json.loads((run_dir / "results.json").read_text())
    if moment in ("import", "compose"):  # no run directory yet: the earlier results are not this run's
        assert done.stderr == ("interrupted by SIGTERM before the run directory was chosen (imports, "
                               "config composition): no results written\n")
        assert results == {"completed": True}
        return
    assert results == {"interrupted": True, "signal": "SIGTERM", "job": "PlanJob", "completed": False,
                       "mcap": None}
    assert done.stderr.endswith(f"results in {run_dir}\n")
