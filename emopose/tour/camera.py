"""The robot's camera as JPEG bytes, for camera-grounded answers (PlanRequest.image).

In simulation that is the MuJoCo model's `head` camera, rendered from the simulator's current state in a
child process of its own (web/pose_renderer.py's PoseRenderer, on the tour scene's file): rendering holds
the GIL (starting its EGL context took 1.1 s here, a frame tens of milliseconds), which in the process
that runs the control loop would hold up a real-time tour's ticks. A backend without a camera gives None
and the question is answered from the dialogue alone; so does a render failure (no EGL on this machine),
logged once: a tour never stops for a picture.
"""

from __future__ import annotations

import logging
from typing import Protocol

import numpy as np

from emopose.backends.capabilities import SimulatedState
from emopose.web.pose_renderer import PoseRenderer, RenderUnavailable

log = logging.getLogger(__name__)


class Camera(Protocol):
    def frame_image(self) -> bytes | None: ...

    def close(self) -> None: ...


class MujocoHeadCamera:
    """The simulator's head camera; its render process starts at the first picture asked for."""

    def __init__(self, backend: SimulatedState, camera: str = "head") -> None:
        self.backend, self.camera = backend, camera
        self.frames = 0
        self._renderer: PoseRenderer | None = None

    def frame_image(self) -> bytes | None:
        if self._renderer is None:
            backend = self.backend
            self._renderer = PoseRenderer(backend.model_path, planar_base=backend.planar_base is not None,
                                          width=backend.renderer.width, height=backend.renderer.height)
            if not self._renderer.start():
                log.warning("head camera unavailable (%s); answering without images", self._renderer.error)
        if not self._renderer.available:
            return None
        try:
            frame = self._renderer.render_jpeg(qpos=np.array(self.backend.data.qpos), camera=self.camera)
        except RenderUnavailable as exc:
            log.warning("head camera frame unavailable (%s); answering without an image", exc)
            return None
        self.frames += 1
        return frame

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()


class NoCamera:
    def frame_image(self) -> bytes | None:
        return None

    def close(self) -> None:
        pass


def camera_for(backend) -> Camera:
    return MujocoHeadCamera(backend) if isinstance(backend, SimulatedState) else NoCamera()
