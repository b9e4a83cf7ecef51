"""The tour's simulated lab: the G1 model plus a colored box (on a post) per object of interest.

write_scene() saves an MJCF next to the run's outputs and points the MuJoCo backend at it before it
connects, so the backend itself stays the plain one (planar base, servos, recorder). Also adds
`tour_overview`, a fixed camera high above the arena that keeps the robot in sight, and drops shadows
and floor reflections, which cost most of a software-rendered frame.
"""

from __future__ import annotations

from pathlib import Path

from emopose.backends.capabilities import SimulatedState
from emopose.tour.scenario import TourSpec

OVERVIEW_CAMERA = "tour_overview"


def build_scene_spec(spec: TourSpec, model_path: str | Path | None = None, fast_render: bool = True):
    """The MjSpec (fixed base: the backend adds the planar joints when it loads the file)."""
    import mujoco

    from emopose.robot.model import build_spec

    scene = build_spec(model_path, planar_base=False)
    world = scene.worldbody
    for obj in spec.objects:
        body = world.add_body(name=f"object_{obj.name}", pos=list(obj.position))
        rgba = [*obj.color, 1.0]
        # Visual only (no contacts): the tour checks clearance itself and the base must not snag.
        body.add_geom(name=f"object_{obj.name}", type=mujoco.mjtGeom.mjGEOM_BOX, size=list(obj.size),
                      rgba=rgba, contype=0, conaffinity=0)
        post = obj.position[2] - obj.size[2]
        if post > 0.02:
            body.add_geom(name=f"post_{obj.name}", type=mujoco.mjtGeom.mjGEOM_CYLINDER,
                          size=[0.02, post / 2, 0], pos=[0, 0, -obj.size[2] - post / 2],
                          rgba=[0.3, 0.3, 0.32, 1], contype=0, conaffinity=0)
    (x_lo, x_hi), (y_lo, y_hi) = spec.arena.x, spec.arena.y
    cx = (x_lo + x_hi) / 2
    span = max(x_hi - x_lo, y_hi - y_lo)
    camera = world.add_camera(name=OVERVIEW_CAMERA, pos=[cx, y_lo - 0.1 * span, 0.4 * span], fovy=60)
    camera.mode = mujoco.mjtCamLight.mjCAMLIGHT_TARGETBODY
    camera.targetbody = "pelvis"
    if fast_render:
        for light in scene.lights:
            light.castshadow = False
        for material in scene.materials:
            material.reflectance = 0.0
        scene.visual.headlight.ambient = [0.5, 0.5, 0.5]  # no shadows: lift the flat lighting a little
    return scene


def write_scene(spec: TourSpec, path: str | Path, model_path: str | Path | None = None,
                fast_render: bool = True) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(build_scene_spec(spec, model_path, fast_render).to_xml())
    return path


def install_scene(backend, spec: TourSpec, run_dir: Path) -> Path | None:
    """Point a not-yet-connected MuJoCo backend at the tour scene (written into run_dir); its path, which
    the tour video is rendered with (emopose/tour/video.py). None: not a simulation."""
    if not isinstance(backend, SimulatedState):
        return None
    if backend.data is not None:
        raise RuntimeError("install_scene must run before the backend connects (before session.open())")
    # mujoco reads MUJOCO_GL at its first import, which is about to happen here rather than in
    # connect(): choose the GL platform the way the backend would.
    backend.select_gl()
    scene = write_scene(spec, run_dir / "tour_scene.xml", backend.model_path)
    backend.model_path = str(scene)
    return scene
