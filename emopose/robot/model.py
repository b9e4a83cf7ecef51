"""Load the G1 upper-body MJCF, optionally with a planar base for the guided tour.

Joint names follow the motion library's order (left arm 0-6, right arm 7-13); the XML's
actuators carry the same names. mujoco is imported inside the functions so importing this
module stays cheap for dry-run code paths.
"""

from __future__ import annotations

import copy
import functools
from pathlib import Path
from typing import TYPE_CHECKING

from emopose.robot import appearance
from emopose.robot.g1_spec import JOINT_NAMES

if TYPE_CHECKING:
    import mujoco

ASSET_PATH = Path(__file__).parent / "assets" / "g1_upper_body.xml"
# Slide x, slide y, hinge yaw (in this order); emopose.backends.planar_base drives them.
BASE_JOINTS: tuple[str, ...] = ("base_x", "base_y", "base_yaw")


class ModelError(ValueError):
    """The MJCF is missing or invalid; the message names the file (config key backend.model_path)."""


def build_spec(
    model_path: str | Path | None = None, planar_base: bool = False, base_kv: float = 400.0,
    meshes: bool = True,
) -> mujoco.MjSpec:
    """The model as an editable MjSpec.

    meshes dresses the robot in Unitree's meshes when the `g1-meshes` extra is installed
    (emopose.robot.appearance: visual-only geoms; the dynamics and contacts stay the model's).
    planar_base adds slide x, slide y and hinge yaw joints on the pelvis (world-frame slides,
    declared before the hinge), each driven by a velocity actuator of the same name, so the tour
    can drive the base like the G1's sport service does (vx, vy, yaw rate).
    """
    import mujoco

    path = Path(model_path or ASSET_PATH)
    if not path.is_file():
        raise ModelError(f"MJCF {path} does not exist; set backend.model_path (null = the packaged model)")
    try:
        spec = mujoco.MjSpec.from_file(str(path))
    except ValueError as exc:  # mujoco reports XML and schema errors as ValueError
        raise ModelError(f"MJCF {path} cannot be loaded: {str(exc).strip()}") from exc
    if meshes:
        appearance.attach_meshes(spec)
    if not planar_base:
        return spec
    pelvis = spec.body("pelvis")
    slide, hinge = mujoco.mjtJoint.mjJNT_SLIDE, mujoco.mjtJoint.mjJNT_HINGE
    for name, jtype, axis in zip(BASE_JOINTS, (slide, slide, hinge), ([1, 0, 0], [0, 1, 0], [0, 0, 1])):
        pelvis.add_joint(name=name, type=jtype, axis=axis, damping=1.0)
        actuator = spec.add_actuator(name=name, target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        # The whole robot is ~20 kg; kv sets how stiffly the base follows the commanded velocity.
        actuator.set_to_velocity(kv=base_kv)
    return spec


def build_model(
    model_path: str | Path | None = None, planar_base: bool = False, meshes: bool = True
) -> mujoco.MjModel:
    """Compile the upper body (fixed base by default).

    Each caller gets its own copy of one compilation per file version: compiling Unitree's meshes takes
    over a second, copying the result a fraction of that.
    """
    path = Path(model_path or ASSET_PATH)
    version = (path.stat().st_mtime_ns, path.stat().st_size) if path.is_file() else None
    dressing = appearance.description_path() if meshes else None
    return copy.copy(_compiled(model_path, version, planar_base, meshes, dressing))


@functools.lru_cache(maxsize=8)
def _compiled(model_path, version, planar_base: bool, meshes: bool, dressing) -> mujoco.MjModel:
    """build_model's compilation; version and dressing (the meshes' source) only key the cache."""
    spec = build_spec(model_path, planar_base=planar_base, meshes=meshes)
    try:
        model = spec.compile()
    except ValueError as exc:
        raise ModelError(f"MJCF {model_path or ASSET_PATH} does not compile: {str(exc).strip()}") from exc
    import mujoco

    # The backend addresses joints and servos by the library's names; say which are missing up front.
    missing = [n for n in JOINT_NAMES if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n) < 0
               or mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, n) < 0]
    if missing:
        raise ModelError(f"MJCF {model_path or ASSET_PATH} lacks the joint or actuator for {missing}")
    return model
