"""g1_check end to end against the fake G1 on loopback DDS (a separate process)."""

import pytest

from emopose import app
from tests.backends.g1.conftest import FakeRobot, require_dds  # noqa: F401 (domain_id fixture)


@pytest.mark.slow
def test_g1_check_runs_one_gesture_and_releases(tmp_path, domain_id, compose):
    require_dds()
    robot = FakeRobot(domain_id, tmp_path / "fake.jsonl", [])
    try:
        cfg = compose("+experiment=g1_check", "planner=keyword", f"backend.domain_id={domain_id}",
                      "backend.weight_ramp_down_s=0.5", "backend.release_blend_s=0.5", "job.gesture=chop_right")
        results = app.run(cfg, tmp_path)
    finally:
        robot.stop()
    assert results["completed"] and results["gesture"] == "chop_right"
    assert [kind for kind, _, _ in results["events"]][:2] == ["started", "completed"]
    # The loop keeps its period on the whole; its timing is measured in benchmarks/g1_publish.py, not
    # here (a loaded test machine misses a few deadlines: 4 of 131 once in a full run).
    assert results["loop"]["missed_deadlines"] <= results["loop"]["ticks"] // 10
    commands = robot.entries("arm")
    assert commands and all(c["crc_ok"] for c in commands)
    assert commands[-1]["weight"] == pytest.approx(0.0, abs=1e-6)  # released
