"""Where a MuJoCo session starts: the library's rest pose unless initial_pose says otherwise (issue 28.7)."""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")  # must precede the first mujoco import

import numpy as np

from emopose.backends.mujoco import MujocoBackend
from emopose.robot.g1_spec import CONTROL_DT
from tests.backends.mujoco_run import NEUTRAL, run_ticks
from tests.wiring import wire

RAISED = np.array([-0.5, 0.2, 0, 1.0, 0, 0, 0, -0.5, -0.2, 0, 1.0, 0, 0, 0])


def test_without_initial_pose_the_arms_are_placed_at_the_first_command():
    backend = MujocoBackend()
    assert backend.connect(None) is None  # nothing chosen: the session starts from the library's neutral
    assert backend.measured() is None
    measured = run_ticks(backend, np.tile(NEUTRAL, (5, 1)))
    backend.close()
    # Placed at rest there, not driven from all-zero joints: within 2 mrad from the first tick on.
    assert np.max(np.abs(measured - NEUTRAL)) < 2e-3


def test_an_explicit_initial_pose_is_where_the_arms_stand():
    backend = MujocoBackend(initial_pose=RAISED.tolist())
    np.testing.assert_allclose(backend.connect(None), RAISED)
    measured = run_ticks(backend, np.tile(NEUTRAL, (1, 1)))
    backend.close()
    assert np.max(np.abs(measured[0] - NEUTRAL)) > 0.4  # one tick from RAISED, still far from NEUTRAL


def test_reset_then_send_does_not_re_place_the_arms():
    backend = MujocoBackend()
    backend.connect(None)
    np.testing.assert_allclose(backend.reset(RAISED), RAISED)
    backend.send(0.0, NEUTRAL)
    moved = backend.measured()
    backend.close()
    assert np.max(np.abs(moved - NEUTRAL)) > 0.4  # tracking from RAISED, not teleported to NEUTRAL


def test_a_session_on_mujoco_starts_at_the_library_rest_pose(g1, tmp_path):
    rest = g1.neutral_entry.q[0]
    wired = wire(g1, tmp_path, backend=MujocoBackend(), record=False)
    wired.session.open()
    np.testing.assert_allclose(wired.sequencer.last, rest)  # the stream's and the safety checks' start
    wired.loop.run_until(lambda: True, CONTROL_DT)
    measured = wired.session.backend.measured()
    wired.session.close()
    assert np.max(np.abs(measured - rest)) < 2e-3
