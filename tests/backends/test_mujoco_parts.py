"""The parts attached to the MuJoCo physics backend by config: the planar base and the renderer."""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")  # must precede the first mujoco import

import numpy as np
import pytest

from emopose.backends.mujoco import MujocoBackend
from emopose.backends.planar_base import MujocoPlanarBase
from emopose.backends.sim_renderer import SimRenderer
from emopose.robot.g1_spec import JOINT_NAMES
from emopose.robot.model import BASE_JOINTS
from tests.backends.mujoco_run import NEUTRAL, run_ticks


def connected(**parts) -> MujocoBackend:
    backend = MujocoBackend(**parts)
    backend.connect(None)
    return backend


def test_planar_base_drives_forward():
    base = MujocoPlanarBase()
    backend = connected(planar_base=base)
    start = backend.data.body("pelvis").xpos.copy()
    base.set_velocity(0.3, 0.0, 0.0)
    run_ticks(backend, np.zeros((50, 14)))
    x = backend.data.body("pelvis").xpos
    # xpos is from the start of the last physics step: 0.3 m/s * 2 ms behind qpos.
    assert base.pose()[:2] == pytest.approx((x[0] - start[0], x[1] - start[1]), abs=1e-3)
    assert base.velocity()[0] == pytest.approx(0.3, abs=0.01)
    backend.close()
    assert 0.25 < x[0] < 0.31 and abs(x[1]) < 0.01


def test_planar_base_commands_are_body_frame_and_place_teleports_at_rest():
    base = MujocoPlanarBase()
    backend = connected(planar_base=base)
    base.place(1.0, -2.0, np.pi / 2)  # facing +y
    assert base.pose() == pytest.approx((1.0, -2.0, np.pi / 2)) and base.velocity() == (0, 0, 0)
    base.set_velocity(0.3, 0.0, 0.0)  # forward in the body frame is +y in the world
    run_ticks(backend, np.zeros((50, 14)))
    x, y, _ = base.pose()
    assert abs(x - 1.0) < 0.01 and 0.25 < y + 2.0 < 0.31
    vx, vy, _ = base.velocity()
    assert vx == pytest.approx(0.3, abs=0.01) and abs(vy) < 0.01


def test_planar_base_refuses_use_before_connect():
    with pytest.raises(RuntimeError, match="before the mujoco backend connected"):
        MujocoPlanarBase().pose()


def test_fixed_base_by_default():
    backend = connected()
    names = {backend.model.joint(i).name for i in range(backend.model.njnt)}
    assert backend.planar_base is None and not names & set(BASE_JOINTS)
    assert backend.model.nq == len(JOINT_NAMES)


def test_default_renderer_renders_nothing_while_running():
    backend = connected()
    run_ticks(backend, np.tile(NEUTRAL, (4, 1)))
    assert backend.renderer.last_frame is None and backend.renderer._offscreen is None  # no GL


def test_render_before_connect_is_a_clear_error():
    with pytest.raises(RuntimeError, match="before connect"):
        MujocoBackend().render_frame()


def _egl_skip_reason() -> str | None:
    try:
        import mujoco

        renderer = mujoco.Renderer(mujoco.MjModel.from_xml_string("<mujoco/>"), 8, 8)
        renderer.close()
    except Exception as exc:  # noqa: BLE001 -- no GPU/EGL driver, or MUJOCO_GL set to something unusable here
        return f"offscreen rendering unavailable (MUJOCO_GL={os.environ.get('MUJOCO_GL')}): {exc}"
    return None


def test_renders_nonblank_frame_video_and_pngs(tmp_path):
    if reason := _egl_skip_reason():
        pytest.skip(reason)
    renderer = SimRenderer(width=320, height=240, every=2, video_path=str(tmp_path / "sim.mp4"),
                           frames_dir=str(tmp_path / "f"))
    backend = connected(renderer=renderer)
    run_ticks(backend, np.tile(NEUTRAL, (5, 1)))
    for camera in ("front", "head"):
        frame = backend.render_frame(camera)
        assert frame.shape == (240, 320, 3) and frame.dtype == np.uint8
        assert frame.std() > 10  # not a flat fill
    assert renderer.last_frame is not None
    backend.close()
    assert (tmp_path / "sim.mp4").stat().st_size > 1000
    assert len(list((tmp_path / "f").glob("frame_*.png"))) == 2  # ticks 2 and 4 of 5


def test_live_renderer_keeps_the_latest_frame(tmp_path):
    if reason := _egl_skip_reason():
        pytest.skip(reason)
    renderer = SimRenderer(width=64, height=48, every=3, live=True)
    backend = connected(renderer=renderer)
    run_ticks(backend, np.tile(NEUTRAL, (2, 1)))
    assert renderer.last_frame is None  # tick 3 is the first rendered one
    run_ticks(backend, np.tile(NEUTRAL, (1, 1)))
    assert renderer.last_frame.shape == (48, 64, 3)
    backend.close()
