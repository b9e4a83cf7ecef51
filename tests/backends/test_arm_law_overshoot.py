"""Issue 28 item 6: under the default arm law the simulated joints stay inside the hard limits and within
1.05x the speed bound, even when every shipped motion is played at intensity 5 from rest as fast as the
commands may go; that takes the limits file's tracking reserve (commands planned below the speed bound
and inside the limits): without it the same law overshoots both."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hydra.utils import instantiate

from emopose import CONTROL_DT
from emopose.backends.mujoco import MujocoBackend
from emopose.execution.trajectory import TrajectoryBuilder
from emopose.joint_limits import JointLimits
from emopose.robot.arm_law import ArmLaw
from emopose.stages.modulate import modulate_keyframes
from emopose.sync.joint_bounds import SPEED_RATIO_BOUND, joint_bounds
from tests.conftest import compose_config


def fastest_commands(g1, limits: JointLimits) -> np.ndarray:
    """Every shipped motion at intensity 5 from rest, each segment as fast as `limits` let it, then back."""
    builder = TrajectoryBuilder(limits)
    rest = g1.neutral_entry.q[0]
    stream = [rest[None]]
    for entry in g1.snapshot.entries.values():
        keyframes = modulate_keyframes(entry.q, 5, g1.limits)
        there = builder.build(keyframes, CONTROL_DT, rest)  # too short: stretched to the speed bound
        back = builder.build(rest, CONTROL_DT, keyframes[-1])
        stream += [there.samples[1:], back.samples[1:], np.repeat(rest[None], 10, axis=0)]
    commands = np.vstack(stream)
    sent = joint_bounds(np.arange(len(commands)) * CONTROL_DT, commands, g1.limits)
    assert sent["speed_ratio_max"] > 0.99 * limits.speed_fraction  # at the planning speed bound
    return commands


def simulated_bounds(law: ArmLaw, commands: np.ndarray, limits: JointLimits) -> dict:
    backend = MujocoBackend(law=law, initial_pose=commands[0].tolist())
    backend.connect(None)
    states = []
    for n, q in enumerate(commands):
        backend.send(n * CONTROL_DT, q)
        states.append(backend.measured().copy())
    backend.close()
    return joint_bounds(np.arange(len(commands)) * CONTROL_DT, np.array(states), limits)


@pytest.fixture(scope="module")
def default_law() -> ArmLaw:
    return instantiate(compose_config([]).arm_law)


def test_the_default_law_keeps_the_joints_inside_the_limits_and_the_speed_bound(g1, default_law):
    assert g1.limits.speed_fraction < 1.0 and g1.limits.limit_margin > 0.0  # the shipped reserve
    measured = simulated_bounds(default_law, fastest_commands(g1, g1.limits), g1.limits)
    assert measured["beyond_limits_max_rad"] == 0.0
    assert measured["speed_ratio_max"] <= SPEED_RATIO_BOUND, measured


def test_without_the_reserve_the_same_law_overshoots(g1, default_law):
    bare = dataclasses.replace(g1.limits, speed_fraction=1.0, limit_margin=0.0)
    measured = simulated_bounds(default_law, fastest_commands(g1, bare), g1.limits)
    assert measured["speed_ratio_max"] > SPEED_RATIO_BOUND and measured["beyond_limits_max_rad"] > 0.0
