"""The G1's recording on one time base (issue: its own messages were stamped with the wall clock since
the recorder opened, its stream with loop time from after the connect, so /g1/lowcmd went back):
every channel only goes forward, and the ramp-up, holds and release sit where they happened."""

from __future__ import annotations

import pytest

from emopose import app
from tests.backends.g1.conftest import FakeRobot, require_dds
from tests.backends.mcap_order import assert_never_back
from tests.backends.test_recording_time_base import PLAN


@pytest.mark.slow
def test_g1_recording_is_monotonic_and_its_phases_in_place(tmp_path, domain_id, compose):
    require_dds()
    robot = FakeRobot(domain_id, tmp_path / "fake.jsonl", [])
    try:
        app.run(compose(*PLAN, "backend=g1", f"backend.domain_id={domain_id}", "backend.weight_ramp_up_s=0.4",
                        "backend.weight_ramp_down_s=0.4", "backend.release_blend_s=0.2"), tmp_path)
    finally:
        robot.stop()
    rows = assert_never_back(tmp_path / "session.mcap")
    lowcmd = rows["/g1/lowcmd"]
    phases = [p["phase"] for _, p in lowcmd]
    first_stream = phases.index("stream")
    assert set(phases[:first_stream]) <= {"ramp_up", "hold"} and phases[-1] == "release"
    # The stream's first command goes out at its loop tick (give or take the tick's lateness).
    commands = rows["/joints/command"]
    assert abs(lowcmd[first_stream][0] - commands[0][0]) < 50e6
    assert lowcmd[first_stream][1]["t"] == pytest.approx(commands[0][1]["t"])
