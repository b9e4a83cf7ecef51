"""Recordings survive kill -9: a real job (plan, serve, tour, sync_eval) SIGKILLed at a random time leaves a
file that emopose.recover turns into a complete one holding every message queued before the last flush
that reached the disk (the Recorder puts a chunk on disk every FLUSH_S), and the recording report reads it.

Which messages existed before which flush comes from a witness (tests/recording/witness.py): the
virtual-clock jobs' log times say nothing about the wall clock, and on a busy machine a flush can land
well after its FLUSH_S, so the test asserts no wall-clock age of the lost tail. Times are drawn per job and
case from a fixed seed, in a window after the recording opened while the job still runs (plan streams ~5 s
of gestures, tour ~10 s, sync_eval ~100 s; serve runs until stopped). The heavier jobs are marked slow.
"""

from __future__ import annotations

import os
import random
import signal
import socket
import subprocess
import sys
import time
from collections import Counter

import pytest

from emopose.config import project_path
from emopose.jobs.recording_report import write_report
from emopose.joint_limits import JointLimits
from emopose.recover import recover
from tests.recording.conftest import PLAN, every_message
from tests.recording.witness import WITNESS, read_witness

KILL_WINDOW_S = (1.5, 4.0)  # after the recording opened: a few flushes in


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


JOBS = {
    "plan": lambda: [*PLAN, "backend=dry_run"],
    "serve": lambda: ["+experiment=serve", "planner=keyword", f"serve.port={_free_port()}"],
    "tour": lambda: ["+experiment=tour_lab", "planner=keyword", "job.video=false"],
    "sync_eval": lambda: ["+experiment=sync_eval", "planner=keyword", "run.record=true", "job.plots=0"],
}
CASES = [pytest.param(job, case, marks=[pytest.mark.slow] if job != "plan" else [], id=f"{job}-{case}")
         for job in JOBS for case in range(3)]


def _killed(run_dir, overrides: list[str], after_s: float) -> None:
    """Run the job with a witness, SIGKILL it `after_s` after its recording appeared."""
    env = {**os.environ, "MUJOCO_GL": "egl", "HF_HUB_OFFLINE": "1", WITNESS: str(run_dir / "witness.txt")}
    job = subprocess.Popen(
        [sys.executable, "-m", "tests.recording.witness", *overrides, f"hydra.run.dir={run_dir}"],
        env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )
    try:
        while not (run_dir / "session.mcap").exists() and job.poll() is None:
            time.sleep(0.02)
        time.sleep(after_s)
        job.send_signal(signal.SIGKILL)
    finally:
        job.wait()
    assert job.returncode == -signal.SIGKILL, f"the job ended before the kill (exit {job.returncode})"


@pytest.mark.parametrize(("job", "case"), CASES)
def test_a_killed_job_is_recovered_up_to_its_last_flush(tmp_path_factory, job, case):
    run_dir = tmp_path_factory.mktemp(f"killed_{job}")  # no brackets: the path is a Hydra override
    after_s = random.Random(f"{job}-{case}").uniform(*KILL_WINDOW_S)
    _killed(run_dir, JOBS[job](), after_s)
    done = recover(run_dir / "session.mcap")
    assert not done.complete, "a killed writer leaves no footer"
    recovered = Counter((stamp, topic) for topic, _, stamp, _ in every_message(done.out))
    witnessed, flushes = read_witness(run_dir / "witness.txt")
    assert flushes, f"killed {after_s:.2f} s in: no flush reached the disk"
    last_flush = max(began for began, _ in flushes)
    old = Counter((stamp, topic) for wall, stamp, topic in witnessed if wall < last_flush)
    lost = old - recovered
    assert not lost, (f"killed {after_s:.2f} s in: lost {sum(lost.values())} flushed messages: "
                      f"{list(lost)[:3]}")
    assert sum(recovered.values()) <= len(witnessed)  # nothing made up
    assert sum(n for (_, topic), n in old.items() if topic == "/joints/command") >= 10, "too early a kill"
    if case == 0:  # the report reads what the recovery wrote
        limits = JointLimits.from_file(project_path("library/g1/limits.yaml"))
        results, _ = write_report(done.out, run_dir / "report", limits, turn_figures=2)
        commands = sum(n for (_, topic), n in recovered.items() if topic == "/joints/command")
        assert results["loop"]["commands"] == commands and (run_dir / "report" / "loop_health.png").is_file()
