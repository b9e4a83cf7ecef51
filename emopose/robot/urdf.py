"""The project's G1 model (robot/assets/g1_upper_body.xml) as a URDF, for Foxglove's 3D panel: every
recording carries it on /robot_description, and /joint_states moves its joints by name.

Made from the compiled MJCF so it cannot drift from it: one link per body, a revolute joint per hinge
(axis and limits from the model), fixed joints elsewhere, and the model's box, sphere and capsule geoms
as visuals (a capsule as a cylinder of its length: URDF has no capsule).
"""

from __future__ import annotations

import math
from functools import lru_cache
from xml.sax.saxutils import quoteattr

import numpy as np

from emopose.robot.model import ASSET_PATH

_HINGE, _BOX, _SPHERE, _CAPSULE = 3, 6, 2, 3  # mjtJoint.mjJNT_HINGE, mjtGeom.mjGEOM_*


def _origin(pos: np.ndarray, quat: np.ndarray) -> str:
    """<origin> of a MuJoCo (w, x, y, z) frame; URDF's rpy: roll about x, then pitch y, then yaw z (fixed)."""
    w, x, y, z = quat
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return f'<origin xyz="{pos[0]:.6g} {pos[1]:.6g} {pos[2]:.6g}" rpy="{roll:.6g} {pitch:.6g} {yaw:.6g}"/>'


def _shape(kind: int, size: np.ndarray) -> str | None:
    if kind == _BOX:
        return f'<box size="{2 * size[0]:.6g} {2 * size[1]:.6g} {2 * size[2]:.6g}"/>'
    if kind == _SPHERE:
        return f'<sphere radius="{size[0]:.6g}"/>'
    if kind == _CAPSULE:
        return f'<cylinder radius="{size[0]:.6g}" length="{2 * size[1] + 2 * size[0]:.6g}"/>'
    return None  # planes and the rest are scenery


def _link(model, body: int) -> str:
    visuals = []
    for g in np.flatnonzero(model.geom_bodyid == body):
        shape = _shape(int(model.geom_type[g]), model.geom_size[g])
        if shape is not None:
            r, gr, b, a = model.geom_rgba[g]
            visuals.append(
                f"<visual>{_origin(model.geom_pos[g], model.geom_quat[g])}<geometry>{shape}</geometry>"
                f'<material name=""><color rgba="{r:.3g} {gr:.3g} {b:.3g} {a:.3g}"/></material></visual>'
            )
    return f"<link name={quoteattr(model.body(body).name)}>{''.join(visuals)}</link>"


def _joint(model, body: int) -> str:
    parent, child = model.body(int(model.body_parentid[body])).name, model.body(body).name
    origin = _origin(model.body_pos[body], model.body_quat[body])
    hinges = [
        j
        for j in range(model.body_jntadr[body], model.body_jntadr[body] + model.body_jntnum[body])
        if model.jnt_type[j] == _HINGE
    ]
    if not hinges:
        return (
            f'<joint name={quoteattr(child + "_fixed")} type="fixed">{origin}'
            f"<parent link={quoteattr(parent)}/><child link={quoteattr(child)}/></joint>"
        )
    j = hinges[0]
    axis, (lo, hi) = model.jnt_axis[j], model.jnt_range[j]
    return (
        f'<joint name={quoteattr(model.joint(j).name)} type="revolute">{origin}'
        f"<parent link={quoteattr(parent)}/><child link={quoteattr(child)}/>"
        f'<axis xyz="{axis[0]:.6g} {axis[1]:.6g} {axis[2]:.6g}"/>'
        f'<limit lower="{lo:.6g}" upper="{hi:.6g}" effort="25" velocity="10"/></joint>'
    )


@lru_cache(maxsize=1)
def robot_urdf() -> str:
    """The URDF text of the G1 upper-body model (world is the root link)."""
    import mujoco

    model = mujoco.MjModel.from_xml_path(str(ASSET_PATH))
    parts = [_link(model, 0)]
    for body in range(1, model.nbody):
        parts += [_link(model, body), _joint(model, body)]
    return f'<?xml version="1.0"?><robot name="g1_upper_body">{"".join(parts)}</robot>'
