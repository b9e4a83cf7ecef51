"""Unitree's meshes dress the robot for the renderers and change nothing else (emopose.robot.appearance).

A small stand-in description (one cube mesh on a body the project models and on one it does not) runs
everywhere; the real holosoma description is checked too where the `g1-meshes` extra is installed.
"""

from __future__ import annotations

import logging
import os

os.environ.setdefault("MUJOCO_GL", "egl")  # must precede the first mujoco import

import mujoco
import numpy as np
import pytest

from emopose.backends.mujoco import MujocoBackend
from emopose.robot import appearance
from emopose.robot.model import build_model, build_spec
from tests.backends.mujoco_run import NEUTRAL, run_ticks

# Left shoulder pitched forward, upper arm yawed inward, forearm raised: the hand meets the chest.
HAND_ON_CHEST = np.concatenate([[-0.6, 0.0, -1.2, -0.5, 0, 0, 0], NEUTRAL[7:]])
CUBE = "\n".join(f"v {x} {y} {z}" for x in (-0.02, 0.02) for y in (-0.02, 0.02) for z in (-0.02, 0.02)) + """
f 1 3 4 2
f 5 6 8 7
f 1 2 6 5
f 3 7 8 4
f 1 5 7 3
f 2 4 8 6
"""
# The hip is not in the project's model: its mesh goes on the pelvis, turned with the hip's frame.
STAND_IN = """<mujoco model="stand_in_g1">
  <compiler angle="radian" meshdir="meshes/"/>
  <default><geom contype="0" conaffinity="0" group="1" density="0"/></default>
  <asset>
    <material name="black" rgba="0.2 0.2 0.2 1"/>
    <mesh name="cube" file="cube.obj"/>
  </asset>
  <worldbody>
    <body name="pelvis" pos="0 0 0.793">
      <freejoint/>
      <inertial pos="0 0 0" mass="3" diaginertia="0.01 0.01 0.01"/>
      <body name="left_hip_pitch_link" pos="0 0.06 -0.1" quat="0.7071068 0 0.7071068 0">
        <inertial pos="0 0 0" mass="1" diaginertia="0.001 0.001 0.001"/>
        <joint axis="0 1 0"/>
        <geom type="mesh" mesh="cube" pos="0.01 0 -0.05" material="black"/>
      </body>
      <body name="left_elbow_link" pos="0.2 0.2 0.2">
        <inertial pos="0 0 0" mass="1" diaginertia="0.001 0.001 0.001"/>
        <joint axis="0 1 0"/>
        <geom type="mesh" mesh="cube" pos="0.05 0 -0.01" rgba="1 0 0 1"/>
        <geom name="elbow_collision" type="capsule" size="0.03" fromto="0 0 0 0.1 0 0" group="3"
              contype="1" conaffinity="1"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


@pytest.fixture
def stand_in(tmp_path, monkeypatch):
    """The stand-in description as if holosoma were installed."""
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "cube.obj").write_text(CUBE)
    (tmp_path / "g1_29dof.xml").write_text(STAND_IN)
    monkeypatch.setattr(appearance, "description_path", lambda: tmp_path / "g1_29dof.xml")


def _added(model) -> list[int]:
    return [g for g in range(model.ngeom) if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH]


def test_meshes_are_visual_only_on_the_right_bodies(stand_in):
    plain, dressed = build_model(meshes=False), build_model()
    hip, elbow = _added(dressed)
    assert dressed.ngeom == plain.ngeom + 2
    assert dressed.body(dressed.geom_bodyid[hip]).name == "pelvis"
    np.testing.assert_allclose(dressed.geom_pos[hip], [-0.05, 0.06, -0.11], atol=1e-6)  # hip frame
    assert dressed.body(dressed.geom_bodyid[elbow]).name == "left_elbow_link"  # moves with the elbow
    np.testing.assert_allclose(dressed.geom_rgba[hip], [0.2, 0.2, 0.2, 1])  # the description's colours
    np.testing.assert_allclose(dressed.geom_rgba[elbow], [1, 0, 0, 1])
    for g in (hip, elbow):
        assert (dressed.geom_contype[g], dressed.geom_conaffinity[g], dressed.geom_group[g]) == (0, 0, 1)
    for g in range(plain.ngeom):  # the project's own geoms: hidden from view, colliding as before
        same = dressed.geom(plain.geom(g).name)
        assert same.group[0] == (appearance.HIDDEN_GROUP if plain.geom_bodyid[g] else plain.geom_group[g])
        assert (same.contype[0], same.conaffinity[0]) == (plain.geom_contype[g], plain.geom_conaffinity[g])
    for field in ("body_mass", "body_inertia", "body_ipos", "dof_armature", "actuator_gainprm"):
        np.testing.assert_array_equal(getattr(dressed, field), getattr(plain, field), err_msg=field)


def _run(stream: np.ndarray) -> tuple[np.ndarray, list, int]:
    backend = MujocoBackend(initial_pose=NEUTRAL.tolist())
    backend.connect(None)
    measured, contacts = [], []
    for q in stream:
        measured.append(run_ticks(backend, q[None])[0])
        contacts.append(backend.contacts())
    meshes = len(_added(backend.model))
    backend.close()
    return np.array(measured), contacts, meshes


def _same_run_with_and_without(monkeypatch, description) -> int:
    """The same command stream with and without the meshes: joint trajectories and contacts agree."""
    ramp = np.linspace(NEUTRAL, HAND_ON_CHEST, 40)
    stream = np.vstack([ramp, np.tile(HAND_ON_CHEST, (20, 1)), ramp[::-1]])
    monkeypatch.setattr(appearance, "description_path", lambda: None)
    plain, plain_contacts, none = _run(stream)
    monkeypatch.setattr(appearance, "description_path", description)
    dressed, dressed_contacts, meshes = _run(stream)
    assert none == 0 and meshes > 0
    np.testing.assert_allclose(dressed, plain, rtol=0, atol=1e-9)
    assert any(plain_contacts), "the stream should press the hand into the chest"
    assert dressed_contacts == plain_contacts
    return meshes


def test_same_commands_same_trajectory_and_contacts(stand_in, monkeypatch):
    assert _same_run_with_and_without(monkeypatch, appearance.description_path) == 2


def test_without_the_package_the_model_is_unchanged_and_said_once(caplog, monkeypatch):
    appearance.description_path.cache_clear()
    monkeypatch.setattr(appearance, "DESCRIPTION", appearance.DESCRIPTION.with_name("absent.xml"))
    with caplog.at_level(logging.INFO, logger=appearance.__name__):
        models = [build_model(), build_model()]
    appearance.description_path.cache_clear()
    plain = build_model(meshes=False)
    assert all(m.ngeom == plain.ngeom and m.nmesh == 0 for m in models)
    assert len([r for r in caplog.records if "holosoma" in r.getMessage()]) == 1


def test_a_file_written_from_a_dressed_spec_is_not_dressed_twice(stand_in, tmp_path):
    path = tmp_path / "scene.xml"
    path.write_text(build_spec().to_xml())  # as the tour writes its scene
    assert len(_added(build_model(path))) == 2


@pytest.mark.slow
@pytest.mark.skipif(appearance.description_path() is None, reason="the g1-meshes extra is not installed")
def test_unitree_meshes_leave_the_dynamics_alone(monkeypatch):
    real = appearance.description_path
    model = build_model()
    arms = {model.body(model.geom_bodyid[g]).name for g in _added(model)}
    assert {f"{side}_{link}_link" for side in ("left", "right") for link in
            ("shoulder_pitch", "shoulder_roll", "shoulder_yaw", "elbow", "wrist_roll", "wrist_pitch",
             "wrist_yaw")} <= arms
    assert _same_run_with_and_without(monkeypatch, real) > 30
