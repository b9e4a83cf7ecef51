"""MuJoCo frames for the web UI, rendered kinematically on one dedicated thread.

Why not the backend's renderer: rendering in the 50 Hz control thread (backend.renderer.live=true) costs
50-1000 ms a frame under software EGL and would make the loop miss its deadlines. Here one worker
thread owns its own model, MjData and Renderer (an EGL context is current in one thread only, and
several contexts created and freed in one process corrupted frames under Mesa), sets the pose to
show (the simulator's full qpos, or 14 joint angles) and renders through robot/render.py's
OffscreenRenderer. Quality 'fast' edits this private model copy to drop MSAA, shadows and
reflections: about 10x cheaper on llvmpipe, so >= 10 fps at 320x240 on a CPU.
"""

from __future__ import annotations

import io
import logging
import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np

log = logging.getLogger(__name__)


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
        self.model_path, self.planar_base = model_path, planar_base
        self.width, self.height, self.quality, self.jpeg_quality = width, height, quality, jpeg_quality
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="emopose-render")
        self._state: dict | None = None
        self.error: str | None = None

    def start(self, timeout_s: float = 120.0) -> bool:
        """Create the renderer on its thread; False (with .error) when rendering is unavailable."""
        try:
            self._pool.submit(self._init).result(timeout=timeout_s)
            return True
        except Exception as exc:  # noqa: BLE001 -- any failure here means "no MuJoCo frames", not a crash
            self.error = f"{type(exc).__name__}: {exc}"[:300]
            log.warning("MuJoCo offscreen rendering unavailable (%s); the UI draws a stick figure",
                        self.error)
            return False

    @property
    def available(self) -> bool:
        return self._state is not None

    def render_jpeg(self, q: np.ndarray | None = None, qpos: np.ndarray | None = None,
                    camera: str = "front", timeout_s: float = 30.0) -> bytes:
        return self.render_many([(q, qpos)], camera, timeout_s)[0]

    def render_many(self, poses: list[tuple[np.ndarray | None, np.ndarray | None]], camera: str = "front",
                    timeout_s: float = 60.0) -> list[bytes]:
        """JPEGs of (q14, full qpos) poses; qpos wins when it fits the model."""
        if self._state is None:
            raise RenderUnavailable(self.error or "renderer not started")
        return self._pool.submit(self._render_all, poses, camera).result(timeout=timeout_s)

    def close(self) -> None:
        def free():
            state, self._state = self._state, None
            if state is not None:
                state["renderer"].close()

        try:
            self._pool.submit(free).result(timeout=10)
        except Exception:  # freeing a context at exit must not mask the real outcome
            log.warning("could not free the web renderer", exc_info=True)
        self._pool.shutdown(wait=False)

    # -- on the render thread ------------------------------------------------------------------
    def _init(self) -> None:
        os.environ.setdefault("MUJOCO_GL", "egl")
        import mujoco

        from emopose.robot.g1_spec import JOINT_NAMES
        from emopose.robot.model import build_model
        from emopose.robot.render import OffscreenRenderer

        model = build_model(self.model_path, planar_base=self.planar_base)
        if self.quality == "fast":  # render-only settings on a private copy; physics never sees it
            model.vis.quality.offsamples = 0
            model.light_castshadow[:] = 0
            model.mat_reflectance[:] = 0.0
        data = mujoco.MjData(model)
        renderer = OffscreenRenderer(model, self.width, self.height)
        qadr = np.array([model.joint(n).qposadr[0] for n in JOINT_NAMES])
        self._state = {"mujoco": mujoco, "model": model, "data": data, "renderer": renderer, "qadr": qadr}
        self._render_all([(np.zeros(len(qadr)), None)], "front")  # fail here, not on the first request

    def _render_all(self, poses, camera: str) -> list[bytes]:
        s = self._state
        mujoco, model, data, renderer = s["mujoco"], s["model"], s["data"], s["renderer"]
        frames = []
        for q, qpos in poses:
            if qpos is not None and len(qpos) == model.nq:
                data.qpos[:] = qpos
            elif q is not None:
                data.qpos[s["qadr"]] = q
            mujoco.mj_kinematics(model, data)
            mujoco.mj_camlight(model, data)  # the head camera moves with the body
            frames.append(encode_jpeg(renderer.render(data, camera), self.jpeg_quality))
        return frames
