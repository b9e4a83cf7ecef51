"""LocoClient against the fake G1's loco service over real DDS."""

from __future__ import annotations

import json
import logging
import time

import pytest

from emopose.backends.g1 import LocoClient, LocoError, LocoTimeoutError


@pytest.fixture(scope="module")
def robot(module_fake_robot):
    return module_fake_robot("--fail-api", "7102:3204")


@pytest.fixture(scope="module")
def client(robot, domain_id):
    with LocoClient(domain_id=domain_id, timeout_s=5.0) as c:
        yield c


def test_fsm_id_round_trip(client):
    assert client.get_fsm_id() == 801
    client.set_fsm_id(500)
    assert client.get_fsm_id() == 500


def test_velocity_is_clamped_logged_and_answered(client, robot, caplog):
    with caplog.at_level(logging.WARNING, logger="emopose.backends.g1.loco"):
        sent = client.set_velocity(1.0, -0.9, 3.0, 0.5)
    assert sent == (0.3, -0.2, 0.5, 0.5)
    assert "vx 1.000 clamped to 0.300" in caplog.text and "omega" in caplog.text
    request = [r for r in robot.wait_for("loco", 1) if r["api_id"] == 7105][-1]
    assert json.loads(request["parameter"]) == {"velocity": [0.3, -0.2, 0.5], "duration": 0.5}
    assert request["code"] == 0


def test_odometry_integrates_the_commanded_velocity(client, robot):
    client.stop()  # cancel what the previous test left running
    client.get_fsm_id()  # any request logs the odometry at that moment
    start = robot.entries("loco")[-1]["odom"]
    client.set_velocity(0.2, 0.0, 0.0, 0.3)
    time.sleep(0.5)
    client.get_fsm_id()
    x, y, yaw = robot.entries("loco")[-1]["odom"]
    # Whatever heading the previous test left, the base moved 0.2 m/s * 0.3 s = 6 cm.
    assert ((x - start[0]) ** 2 + (y - start[1]) ** 2) ** 0.5 == pytest.approx(0.06, abs=0.005)
    assert yaw == pytest.approx(start[2])


def test_non_zero_status_raises_with_api_id_and_code(client):
    with pytest.raises(LocoError, match="loco api 7102 failed with status code 3204") as err:
        client.call(7102, {"data": 1})
    assert (err.value.api_id, err.value.code) == (7102, 3204)
    with pytest.raises(LocoError, match="3203"):  # not implemented by the server
        client.call(7999, {})


def test_timeout_is_a_clear_error(robot, domain_id):
    expected = r"loco api 7001: no loco service 'no_such_service'"
    with (
        LocoClient(domain_id=domain_id, service="no_such_service", timeout_s=0.3) as lonely,
        pytest.raises(LocoTimeoutError, match=expected),
    ):
        lonely.get_fsm_id()


def test_non_finite_velocity_is_refused_before_sending(client):
    with pytest.raises(ValueError, match="vx must be finite"):
        client.set_velocity(float("nan"), 0.0, 0.0)
