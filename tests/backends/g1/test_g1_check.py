"""g1_check end to end against the fake G1 on loopback DDS (a separate process), and robot faults as
results in every job (g1_check and plan here, one mechanism: emopose/jobs/robot_fault.py):
results.json/results.md written, times relative to the run, exit 3 with one line, no traceback."""

import json
import os
import subprocess
import sys
import threading

import pytest

from emopose import app
from emopose.config import PROJECT_ROOT
from emopose.jobs.robot_fault import ROBOT_FAULT_EXIT, RobotFault
from tests.backends.g1.conftest import FakeRobot, require_dds  # noqa: F401 (domain_id fixture)

FAST = ("backend.weight_ramp_up_s=0.2", "backend.weight_ramp_down_s=0.5", "backend.release_blend_s=0.5")


def results_of(run_dir) -> dict:
    assert (run_dir / "results.md").is_file()
    return json.loads((run_dir / "results.json").read_text())


@pytest.mark.slow
def test_g1_check_runs_one_gesture_and_releases(tmp_path, domain_id, compose):
    require_dds()
    robot = FakeRobot(domain_id, tmp_path / "fake.jsonl", [])
    try:
        # The fake robot is another process: in one full run on the loaded 2-core machine its state
        # stream paused 224 ms, over the 200 ms loss limit, and the check faulted as designed. Loss is
        # tested below and in test_g1_faults.py; here a longer limit keeps the happy path about itself.
        cfg = compose("+experiment=g1_check", "planner=keyword", f"backend.domain_id={domain_id}", *FAST,
                      "job.gesture=chop_right", "backend.lowstate_loss_ms=1000")
        results = app.run(cfg, tmp_path)
    finally:
        robot.stop()
    assert results["completed"] and results["gesture"] == "chop_right" and results["fault"] is None
    kinds = [kind for kind, _, _ in results["events"]]
    assert kinds[0] == "started" and "completed" in kinds
    times = [t for _, _, t in results["events"]]
    assert 0 < times[0] <= times[-1] < 60  # seconds since the run started, not perf_counter values
    # The loop keeps its period on the whole; its timing is measured in benchmarks/g1_publish.py, not
    # here (a loaded test machine misses a few deadlines: 4 of 131 once in a full run).
    assert results["loop"]["missed_deadlines"] <= results["loop"]["ticks"] // 10
    commands = robot.entries("arm")
    assert commands and all(c["crc_ok"] for c in commands)
    assert commands[-1]["weight"] == pytest.approx(0.0, abs=1e-6)  # released


def test_no_robot_is_a_fault_result_not_a_traceback(tmp_path, domain_id, compose):
    require_dds()
    cfg = compose("+experiment=g1_check", "planner=keyword", f"backend.domain_id={domain_id}",
                  "backend.lowstate_timeout_s=0.3")
    with pytest.raises(RobotFault) as fault:
        app.run(cfg, tmp_path)
    assert "G1CheckJob: robot FAULT" in str(fault.value) and "rt/lowstate" in str(fault.value)
    results = results_of(tmp_path)
    assert "refusing to start" in results["fault"] and not results["completed"]
    assert 0 <= results["fault_at_s"] < 30 and results["events"] == []
    assert "FAULT at" in (tmp_path / "results.md").read_text()


@pytest.mark.slow
def test_robot_lost_mid_gesture_is_a_fault_result(tmp_path, domain_id, compose):
    require_dds()
    robot = FakeRobot(domain_id, tmp_path / "fake.jsonl", ["--duration", "2.0"])  # vanishes mid-run
    try:
        cfg = compose("+experiment=g1_check", "planner=keyword", f"backend.domain_id={domain_id}", *FAST,
                      "job.gesture=chop_right", "backend.lowstate_timeout_s=5")
        with pytest.raises(RobotFault):
            app.run(cfg, tmp_path)
    finally:
        robot.stop()
    results = results_of(tmp_path)
    assert "rt/lowstate" in results["fault"] and not results["completed"]
    assert 0 < results["fault_at_s"] < 30 and results["gesture"] == "chop_right"
    assert all(0 < t <= results["fault_at_s"] for _, _, t in results["events"])


@pytest.mark.slow
def test_plan_on_a_robot_lost_mid_turn_is_a_fault_result(tmp_path, domain_id, compose):
    """Before, plan ended a G1 fault in a traceback with no results.json."""
    require_dds()
    robot = FakeRobot(domain_id, tmp_path / "fake.jsonl", [])
    # It vanishes mid-turn: after 40 commands (0.8 s of the stream, past the 0.2 s ramp-up), planning
    # and synthesis before the session opens taking whatever they take.
    vanish = threading.Thread(target=lambda: (robot.wait_for("arm", 40, timeout_s=120), robot.kill()))
    vanish.start()
    try:
        cfg = compose("+experiment=plan", "planner=keyword", "backend=g1", f"backend.domain_id={domain_id}",
                      *FAST, "backend.lowstate_timeout_s=5",
                      "utterance='Welcome everyone, please look over there at the big screen.'")
        with pytest.raises(RobotFault, match="PlanJob: robot FAULT at .* lost rt/lowstate"):
            app.run(cfg, tmp_path)
    finally:
        vanish.join()
        robot.stop()
    results = results_of(tmp_path)
    assert "rt/lowstate" in results["fault"] and not results["completed"] and results["job"] == "PlanJob"
    assert results["utterance"].startswith("Welcome") and 0 < results["fault_at_s"] < 30


@pytest.mark.slow
@pytest.mark.parametrize("job", ["+experiment=g1_check", "+experiment=plan"])
def test_cli_fault_exits_3_with_one_line(tmp_path, domain_id, job):
    require_dds()
    env = {**os.environ, "HF_HUB_OFFLINE": "1"}
    done = subprocess.run([sys.executable, "-m", "emopose", job, "planner=keyword", "backend=g1",
                           f"backend.domain_id={domain_id}", "backend.lowstate_timeout_s=0.3",
                           f"hydra.run.dir={tmp_path}"],
                          cwd=PROJECT_ROOT, env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == ROBOT_FAULT_EXIT and "Traceback" not in done.stderr, done.stderr[-2000:]
    assert "robot FAULT" in done.stderr.strip().splitlines()[-1]
    assert "refusing to start" in results_of(tmp_path)["fault"]
