"""Offscreen rendering of the G1 model and writing frames to video / PNG.

MUJOCO_GL must be chosen before mujoco is first imported (egl headless); the backend sets it.
An EGL context can be current in only one thread, and the web UI renders from worker threads,
so each thread gets its own mujoco.Renderer.
"""

from __future__ import annotations

import logging
import threading
from pathlib import Path

import numpy as np

log = logging.getLogger(__name__)


class OffscreenRenderer:
    """Per-thread mujoco.Renderer instances over one model."""

    def __init__(self, model, width: int, height: int) -> None:
        self.model, self.width, self.height = model, width, height
        self._by_thread: dict[int, object] = {}
        self._lock = threading.Lock()

    def _renderer(self):
        import mujoco

        key = threading.get_ident()
        with self._lock:
            if key not in self._by_thread:
                self._by_thread[key] = mujoco.Renderer(self.model, self.height, self.width)
            return self._by_thread[key]

    def render(self, data, camera: str | int = -1) -> np.ndarray:
        renderer = self._renderer()
        renderer.update_scene(data, camera=camera)
        return renderer.render()

    def close(self) -> None:
        with self._lock:
            renderers, self._by_thread = list(self._by_thread.values()), {}
        for renderer in renderers:
            try:
                renderer.close()
            except (
                Exception
            ):  # a context made in another (maybe finished) thread may refuse to be freed
                log.warning("could not free an offscreen renderer", exc_info=True)


class FrameSink:
    """Writes frames to an MP4 (imageio-ffmpeg) and/or numbered PNGs; either may be None."""

    def __init__(self, video_path: str | None, frames_dir: str | None, fps: float) -> None:
        import imageio.v2 as imageio

        self._imageio = imageio
        self._writer = None
        if video_path:
            Path(video_path).parent.mkdir(parents=True, exist_ok=True)
            # macro_block_size=1 keeps odd frame sizes as they are instead of resizing them.
            self._writer = imageio.get_writer(
                video_path, fps=fps, codec="libx264", macro_block_size=1
            )
        self._frames_dir = Path(frames_dir) if frames_dir else None
        if self._frames_dir:
            self._frames_dir.mkdir(parents=True, exist_ok=True)
        self._count = 0

    def add(self, frame: np.ndarray) -> None:
        if self._writer is not None:
            self._writer.append_data(frame)
        if self._frames_dir is not None:
            self._imageio.imwrite(self._frames_dir / f"frame_{self._count:05d}.png", frame)
        self._count += 1

    def close(self) -> None:
        if self._writer is not None:
            self._writer.close()
            self._writer = None
