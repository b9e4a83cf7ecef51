"""Navigation: the go-to-pose controller, the MuJoCo planar base, the G1 base on the fake robot."""

from __future__ import annotations

import math
import os

import numpy as np
import pytest

os.environ.setdefault("MUJOCO_GL", "egl")

from emopose.backends.mujoco import MujocoBackend
from emopose.backends.planar_base import MujocoPlanarBase
from emopose.scene.geometry import Pose2D, wrap_angle
from emopose.tour.controller import GoToPose
from emopose.tour.g1_base import G1Base
from emopose.tour.navigator import NavigationSettings, Navigator
from emopose.tour.scenario_loading import load_tour
from emopose.tour.sim_base import MujocoBase
from tests.tour.tour_helpers import LAB_FILE


def unicycle(goal: Pose2D, start: Pose2D, dt: float = 0.02) -> tuple[Pose2D, list[float], int]:
    pose, speeds = start, []
    controller = GoToPose(goal, dt=dt)
    for tick in range(20000):
        if controller.done:
            return pose, speeds, tick
        vx, wz = controller.update(pose)
        speeds.append(vx)
        pose = Pose2D(pose.x + vx * math.cos(pose.yaw) * dt, pose.y + vx * math.sin(pose.yaw) * dt,
                      wrap_angle(pose.yaw + wz * dt))
    raise AssertionError(f"controller never finished: phase {controller.phase}")


@pytest.mark.parametrize("seed", range(6))
def test_controller_turns_drives_and_turns_to_the_goal(seed):
    rng = np.random.default_rng(seed)
    goal = Pose2D(*rng.uniform(-3, 3, 2), rng.uniform(-math.pi, math.pi))
    pose, speeds, _ = unicycle(goal, Pose2D(0.0, 0.0, rng.uniform(-math.pi, math.pi)))
    assert pose.distance_to(goal) < 0.01
    assert abs(pose.heading_error_to(goal)) <= math.radians(4.0)
    assert max(speeds) <= 0.3 + 1e-9 and min(speeds) >= 0.0  # never faster than 0.3 m/s, never backwards


def test_controller_at_the_goal_only_turns_and_refuses_fast_settings():
    pose, speeds, _ = unicycle(Pose2D(0.0, 0.0, 1.0), Pose2D(0.0, 0.0, 0.0))
    assert max(speeds) == 0.0 and abs(pose.yaw - 1.0) <= math.radians(4.0)
    with pytest.raises(ValueError, match="0.3"):
        GoToPose(Pose2D(1, 0, 0), max_vx=0.5)


def sim_navigator(velocity_std=0.0, yaw_rate_std=0.0, seed=0):
    backend = MujocoBackend(planar_base=MujocoPlanarBase(), initial_pose=[0.0] * 14)  # arms held down
    q0 = backend.connect(None)
    base = MujocoBase(backend.planar_base, velocity_std, yaw_rate_std, seed)
    clock = [0.0]

    def advance():
        backend.send(clock[0], q0)
        base.after_tick(0.02)
        clock[0] += 0.02

    return base, Navigator(base, NavigationSettings(), advance, lambda: clock[0])


def test_mujoco_base_reaches_the_four_lab_stops():
    base, navigator = sim_navigator()
    for stop in load_tour(LAB_FILE).stops_in_order:
        leg = navigator.go_to(stop.pose.pose())
        truth = base.true_pose()
        assert leg.reached, stop.name
        assert truth.distance_to(leg.goal) < 0.03, stop.name  # target: 0.10 m
        assert abs(truth.heading_error_to(leg.goal)) <= math.radians(4.0)
        assert not base.moving()
        assert leg.odometry_error_m == pytest.approx(truth.distance_to(leg.goal), abs=0.005)  # no noise


def test_walking_is_a_command_in_force_not_the_sway_of_gesturing_arms():
    backend = MujocoBackend(planar_base=MujocoPlanarBase(), initial_pose=[0.0] * 14)
    q0 = backend.connect(None)
    base = MujocoBase(backend.planar_base)

    def advance(periods: int = 1) -> None:
        for _ in range(periods):
            backend.send(0.0, q0)
            base.after_tick(0.02)

    base.command(0.2, 0.0)
    advance(10)
    assert base.moving()
    base.stop()
    assert base.moving()  # still coasting: not yet at rest after the stop
    advance(50)
    assert not base.moving()
    backend.data.qvel[backend.model.joint("base_x").dofadr[0]] = 0.05  # the arms' reaction push at a stop
    assert base.true_velocity()[0] > base.rest_speed and not base.moving()
    base.command(0.0, 0.3)
    assert base.moving()


def test_noisy_odometry_is_seeded_and_still_within_tolerance():
    finals = []
    for _ in range(2):
        base, navigator = sim_navigator(velocity_std=0.01, yaw_rate_std=0.01, seed=7)
        errors = []
        for stop in load_tour(LAB_FILE).stops_in_order:
            goal = navigator.go_to(stop.pose.pose()).goal
            errors.append(base.true_pose().distance_to(goal))
        finals.append(base.true_pose())
        assert max(errors) < 0.15
    assert finals[0] == finals[1]  # same seed, same drift
    base, navigator = sim_navigator(velocity_std=0.01, yaw_rate_std=0.01, seed=8)
    navigator.go_to(Pose2D(1.2, 0.0, 0.0))
    assert base.odometry() != base.true_pose()  # the noise is real


def test_a_pause_stops_the_base_before_the_handler_runs():
    base, navigator = sim_navigator()
    seen = []

    def handle(event):
        seen.append((event, base.moving(), base.true_pose()))
        return True

    leg = navigator.go_to(Pose2D(1.5, 0.0, 0.0), poll=lambda t: "question" if 2.0 <= t < 2.02 else None,
                          handle=handle)
    assert leg.reached and leg.pauses == 1
    assert seen[0][0] == "question" and seen[0][1] is False  # at rest when the answer starts
    assert 0.2 < seen[0][2].x < 1.4  # stopped part way, then resumed
    leg = navigator.go_to(Pose2D(0.0, 0.0, 0.0), poll=lambda t: "stop" if t > 1.0 else None,
                          handle=lambda e: False)
    assert not leg.reached and not base.moving()  # an abort ends the leg with the base at rest


class FakeLoco:
    def __init__(self):
        self.sent = []

    def set_velocity(self, vx, vy, omega, duration=1.0):
        self.sent.append((vx, vy, omega, duration))

    def stop(self):
        self.set_velocity(0.0, 0.0, 0.0, 0.0)


def test_g1_base_maps_odometry_onto_the_map_and_rate_limits():
    raw = [Pose2D(2.0, 1.0, math.pi / 2)]
    now = [0.0]
    base = G1Base(FakeLoco(), lambda: raw[0], origin=Pose2D(5.0, 0.0, 0.0), clock=lambda: now[0])
    assert base.odometry().distance_to(Pose2D(5.0, 0.0, 0.0)) < 1e-9
    raw[0] = Pose2D(2.0, 2.0, math.pi / 2)  # one metre along the robot's heading (its +y)
    moved = base.odometry()
    assert (moved.x, moved.y) == pytest.approx((6.0, 0.0)) and moved.yaw == pytest.approx(0.0)
    for k in range(10):  # 10 calls within 50 ms: one command on the wire
        now[0] = k * 0.005
        base.command(0.2, 0.0)
    assert len(base.loco.sent) == 1 and base.loco.sent[0][3] == 0.5
    base.stop()
    assert base.loco.sent[-1] == (0.0, 0.0, 0.0, 0.0) and base.moving()
    now[0] += 1.0
    assert not base.moving()
