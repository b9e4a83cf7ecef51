"""The tour's navigation on the G1 path: LocoClient.set_velocity to the fake robot, odometry back.

The fake G1 (its own process, real Cyclone DDS on loopback) integrates the commanded velocity into
its odometry; it reports that odometry in its log on every loco request, so the test's odometry
source asks for the FSM id (a cheap RPC) and reads the pose from the newest log line.
"""

from __future__ import annotations

import json
import math
import random
import time

import pytest

from emopose.scene.geometry import Pose2D
from emopose.tour.g1_base import G1Base
from emopose.tour.navigator import NavigationSettings, Navigator
from tests.backends.g1.conftest import FakeRobot, require_dds


@pytest.fixture
def robot(tmp_path):
    require_dds()
    fake = FakeRobot(random.SystemRandom().randint(20, 230), tmp_path / "fake.jsonl", [])
    yield fake
    fake.stop()


class FakeRobotOdometry:
    """The fake robot's integrated odometry, as fresh as one RPC round trip."""

    def __init__(self, loco, robot: FakeRobot) -> None:
        self.loco, self.robot = loco, robot

    def __call__(self) -> Pose2D:
        self.loco.get_fsm_id()  # the fake logs its odometry with every request it answers
        with open(self.robot.log_path, "rb") as log:
            log.seek(0, 2)
            start = max(0, log.tell() - 4096)
            log.seek(start)
            tail = log.read().splitlines()[1 if start else 0:]  # the first line may be cut
            lines = [json.loads(line) for line in tail if line.strip()]
        x, y, yaw = [line for line in lines if line["kind"] == "loco"][-1]["odom"]
        return Pose2D(x, y, yaw)


def test_g1_base_walks_to_a_pose_on_onboard_odometry(robot):
    from emopose.backends.g1 import LocoClient

    with LocoClient(domain_id=robot.domain_id, timeout_s=2.0) as loco:
        start = Pose2D(1.0, 2.0, math.pi / 2)  # where the tour says the robot stands
        base = G1Base(loco, FakeRobotOdometry(loco, robot), origin=start)
        navigator = Navigator(base, NavigationSettings(stop_tolerance_m=0.10), lambda: time.sleep(0.02),
                              time.monotonic)
        goal = Pose2D(1.4, 2.25, 0.0)  # 0.47 m ahead-right, then face east
        leg = navigator.go_to(goal)
    assert leg.reached
    assert leg.odometry_error_m <= 0.10
    assert abs(leg.odometry.heading_error_to(goal)) <= math.radians(6.0)
    velocities = [json.loads(r["parameter"]) for r in robot.entries("loco") if r["api_id"] == 7105]
    assert max(v["velocity"][0] for v in velocities) <= 0.3 + 1e-9  # indoor speed limit on the wire
    assert min(v["velocity"][0] for v in velocities) >= 0.0
    assert velocities[-1] == {"velocity": [0.0, 0.0, 0.0], "duration": 0.0}  # it ends with a stop
    assert all(0.0 < v["duration"] <= 0.5 for v in velocities[:-1])  # each command expires by itself
