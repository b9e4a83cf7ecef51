"""The robot's camera as PNG bytes, for camera-grounded answers (PlanRequest.image).

In simulation that is the MuJoCo model's `head` camera (a frame rendered offscreen); a backend
without a camera gives None and the question is answered from the dialogue alone. A render
failure (no EGL on this machine) is logged and also gives None: a tour never stops for a picture.
"""

from __future__ import annotations

import io
import logging
from typing import Protocol

from emopose.backends.capabilities import Renderable

log = logging.getLogger(__name__)


class Camera(Protocol):
    def frame_png(self) -> bytes | None: ...


def png_bytes(frame) -> bytes:
    import imageio.v3 as iio

    buffer = io.BytesIO()
    iio.imwrite(buffer, frame, extension=".png")
    return buffer.getvalue()


class MujocoHeadCamera:
    def __init__(self, backend, camera: str = "head") -> None:
        self.backend, self.camera = backend, camera
        self.frames = 0

    def frame_png(self) -> bytes | None:
        try:
            frame = self.backend.render_frame(self.camera)
        except Exception as exc:  # noqa: BLE001 - no GL context here: answer without the picture
            log.warning("head camera frame unavailable (%s); answering without an image", exc)
            return None
        self.frames += 1
        return png_bytes(frame)


class NoCamera:
    def frame_png(self) -> bytes | None:
        return None


def camera_for(backend) -> Camera:
    return MujocoHeadCamera(backend) if isinstance(backend, Renderable) else NoCamera()
