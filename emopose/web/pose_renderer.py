"""MuJoCo frames for the web UI, rendered kinematically in a child process of their own.

Why not the backend's renderer: rendering in the 50 Hz control thread (backend.renderer.live=true) costs
50-1000 ms a frame under software EGL and would make the loop miss its deadlines. Why not a thread:
rendering and JPEG encoding hold the GIL for about 14 ms a frame, so the loop thread, however high its
priority, waited behind them (gaps of 80 ms between commands with two pages watching). So one child
process (emopose.child_process) owns its own model, MjData and Renderer, at a lower CPU priority than
the server; it sets the pose to show (the simulator's full qpos, or 14 joint angles), renders through
robot/render.py's OffscreenRenderer and answers JPEG bytes. Quality 'fast' edits this private model
copy to drop MSAA, shadows and reflections: about 10x cheaper on llvmpipe, so >= 10 fps at 320x240.
"""

from __future__ import annotations

import io
import logging
import os
import threading

import numpy as np

from emopose.child_process import ChildProcess, ChildProcessGone, serve_requests

log = logging.getLogger(__name__)

RENDER_NICENESS = 5  # frames for the page yield the CPU to planning and speech synthesis


class RenderUnavailable(RuntimeError):
    """Offscreen rendering cannot run here (no EGL, no mujoco); the UI falls back to the stick figure."""


def encode_jpeg(image: np.ndarray, quality: int = 80) -> bytes:
    from PIL import Image  # pillow ships with imageio

    buffer = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(image)).save(buffer, "JPEG", quality=quality)
    return buffer.getvalue()


class PoseRenderer:
    def __init__(self, model_path: str | None = None, planar_base: bool = False, width: int = 320,
                 height: int = 240, quality: str = "fast", jpeg_quality: int = 80) -> None:
        self.settings = (model_path, planar_base, width, height, quality, jpeg_quality)
        self._child: ChildProcess | None = None
        self._lock = threading.Lock()  # one request at a time on the pipe
        self.error: str | None = None

    def start(self, timeout_s: float = 120.0) -> bool:
        """Start the render process; False (with .error) when rendering is unavailable."""
        try:
            self._child = ChildProcess("emopose.web.pose_renderer", "serve_frames", *self.settings,
                                       name="frame renderer")
            self._child.receive(timeout_s)
            return True
        except Exception as exc:  # noqa: BLE001 -- any failure here means "no MuJoCo frames", not a crash
            self.error = f"{type(exc).__name__}: {exc}"[:300]
            self.close()
            log.warning("MuJoCo offscreen rendering unavailable (%s); the UI draws a stick figure",
                        self.error)
            return False

    @property
    def available(self) -> bool:
        return self._child is not None and self._child.alive

    def render_jpeg(self, q: np.ndarray | None = None, qpos: np.ndarray | None = None,
                    camera: str = "front", timeout_s: float = 30.0) -> bytes:
        return self.render_many([(q, qpos)], camera, timeout_s)[0]

    def render_many(self, poses: list[tuple[np.ndarray | None, np.ndarray | None]], camera: str = "front",
                    timeout_s: float = 60.0) -> list[bytes]:
        """JPEGs of (q14, full qpos) poses; qpos wins when it fits the model."""
        with self._lock:
            if not self.available:
                raise RenderUnavailable(self.error or "renderer not started")
            try:
                return self._child.request((poses, camera), timeout_s)
            except ChildProcessGone as exc:
                self.error = str(exc)
                raise RenderUnavailable(self.error) from exc

    def close(self) -> None:
        with self._lock:
            child, self._child = self._child, None
        if child is not None:
            child.close()


def serve_frames(*settings) -> None:
    """The render process (started by PoseRenderer.start)."""
    serve_requests(lambda: _FrameRenderer(*settings).render_all)


class _FrameRenderer:
    """In the render process: a private model copy, its MjData and one offscreen renderer."""

    def __init__(self, model_path, planar_base, width, height, quality, jpeg_quality) -> None:
        os.nice(RENDER_NICENESS)
        os.environ.setdefault("MUJOCO_GL", "egl")
        import mujoco

        from emopose.robot.g1_spec import JOINT_NAMES
        from emopose.robot.model import build_model
        from emopose.robot.render import OffscreenRenderer

        model = build_model(model_path, planar_base=planar_base)
        if quality == "fast":  # render-only settings on a private copy; physics never sees it
            model.vis.quality.offsamples = 0
            model.light_castshadow[:] = 0
            model.mat_reflectance[:] = 0.0
        self.mujoco, self.model, self.data = mujoco, model, mujoco.MjData(model)
        self.renderer = OffscreenRenderer(model, width, height)
        self.jpeg_quality = jpeg_quality
        self.qadr = np.array([model.joint(n).qposadr[0] for n in JOINT_NAMES])
        self.render_all(([(np.zeros(len(self.qadr)), None)], "front"))  # fail here, not on a request

    def render_all(self, request) -> list[bytes]:
        poses, camera = request
        frames = []
        for q, qpos in poses:
            if qpos is not None and len(qpos) == self.model.nq:
                self.data.qpos[:] = qpos
            elif q is not None:
                self.data.qpos[self.qadr] = q
            self.mujoco.mj_kinematics(self.model, self.data)
            self.mujoco.mj_camlight(self.model, self.data)  # the head camera moves with the body
            frames.append(encode_jpeg(self.renderer.render(self.data, camera), self.jpeg_quality))
        return frames
