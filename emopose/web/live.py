"""Wiring a LiveSession for serving: the MuJoCo frame renderer, the camera, the frame pump.

The simulation channel exists only with backend=mujoco (it shows the simulated state, frames
>= 10 fps); with dry_run the page draws the stick figure from the command stream instead. The
camera channel is a webcam when OpenCV finds one, else the robot's 'head' camera rendered from the
current pose. Without EGL both fall back: the stick figure stays, the camera panel hides.
"""

from __future__ import annotations

import logging

from emopose.backends.capabilities import SimulatedState
from emopose.resources import Run
from emopose.web.frames import Channel, FramePump, Webcam
from emopose.web.pose_renderer import PoseRenderer
from emopose.web.session import LiveSession
from emopose.web.settings import ServeSettings

log = logging.getLogger(__name__)


def open_session(run: Run, settings: ServeSettings, render: bool = True) -> LiveSession:
    """Build the session's image sources; `render=False` skips MuJoCo entirely (fast API tests)."""
    renderer = None
    if render:
        backend = run.resources.backend
        model_path, planar = ((backend.model_path, backend.planar_base is not None)
                              if isinstance(backend, SimulatedState) else (None, False))
        renderer = PoseRenderer(model_path, planar,
                                settings.render_width, settings.render_height, settings.render_quality)
        renderer.start()
    session = LiveSession(run, settings, renderer=renderer)
    channels = []
    rendering = renderer is not None and renderer.available
    if rendering and isinstance(run.resources.backend, SimulatedState):
        channels.append(Channel("sim", settings.sim_fps, _renderer_view(session, settings.sim_camera),
                                f"MuJoCo '{settings.sim_camera}' camera"))
    camera = _camera_channel(session, settings, rendering)
    if camera is not None:
        channels.append(camera)
    session.frames = FramePump(channels)
    session.frames.start()
    return session


def _renderer_view(session: LiveSession, camera: str):
    def produce() -> bytes:
        q, qpos = session.pose()
        return session.renderer.render_jpeg(q, qpos, camera)

    return produce


def _camera_channel(session: LiveSession, settings: ServeSettings, rendering: bool) -> Channel | None:
    if settings.camera == "off" or settings.camera_fps <= 0:
        return None
    if settings.camera in ("auto", "webcam"):
        webcam = Webcam.open(settings.webcam_index)
        if webcam is not None:
            session.webcam = webcam
            return Channel("camera", settings.camera_fps, webcam.read_jpeg, f"webcam {settings.webcam_index}")
        if settings.camera == "webcam":
            log.warning("serve.camera=webcam but no camera opened (OpenCV missing or no device)")
            return None
    if not rendering:
        return None
    return Channel("camera", settings.camera_fps, _renderer_view(session, settings.head_camera),
                   f"simulated '{settings.head_camera}' camera")
