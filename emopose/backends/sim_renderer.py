"""SimRenderer: offscreen images of a MujocoBackend's state, attached to it by config.

On demand, render_frame(camera) draws the current state (jobs, the tour's head camera). While the
backend runs, every `every` control ticks it renders the configured camera, keeps the frame as
last_frame when `live` (for a UI that reads it instead of rendering itself) and writes it to
video_path (MP4) and/or frames_dir (numbered PNGs). Nothing is rendered per tick unless one of
those three asks for it, so the default costs nothing. Rendering happens on the control thread,
under the backend's lock, as before the split (conf/backend/mujoco.yaml, `renderer:`).
"""

from __future__ import annotations

import threading
from typing import Any

import numpy as np

from emopose.robot.g1_spec import CONTROL_DT
from emopose.robot.render import FrameSink, OffscreenRenderer


class SimRenderer:
    def __init__(
        self,
        width: int = 640,
        height: int = 480,
        camera: str = "front",
        every: int = 2,
        live: bool = False,
        video_path: str | None = None,
        frames_dir: str | None = None,
    ) -> None:
        self.width, self.height, self.camera = width, height, camera
        self.every = max(1, int(every))  # ticks between frames: 2 -> 25 fps
        self.live = live
        self.video_path, self.frames_dir = video_path, frames_dir
        self.last_frame: np.ndarray | None = None
        self._model = self._data = None
        self._lock: threading.RLock | None = None
        self._offscreen: OffscreenRenderer | None = None
        self._sink: FrameSink | None = None

    def attach(self, model: Any, data: Any, lock: threading.RLock) -> None:
        """Bind to a freshly connected simulation (the backend calls this in connect())."""
        self.close()
        self._model, self._data, self._lock = model, data, lock
        self.last_frame = None
        if self.video_path or self.frames_dir:
            self._sink = FrameSink(self.video_path, self.frames_dir, 1.0 / (CONTROL_DT * self.every))

    def render_frame(self, camera: Any = None) -> np.ndarray:
        """One (height, width, 3) uint8 image of the current state (offscreen, EGL by default)."""
        if self._data is None:
            raise RuntimeError("mujoco backend: render_frame() before connect()")
        if self._offscreen is None:
            self._offscreen = OffscreenRenderer(self._model, self.width, self.height)
        with self._lock:
            return self._offscreen.render(self._data, camera or self.camera)

    def after_tick(self, tick: int) -> None:
        """Called by the backend after each control period's physics."""
        if (self.live or self._sink is not None) and tick % self.every == 0:
            self.last_frame = self.render_frame()
            if self._sink is not None:
                self._sink.add(self.last_frame)

    def close(self) -> None:
        """Finish the video and free the GL contexts; render_frame() still works afterwards."""
        if self._sink is not None:
            self._sink.close()
            self._sink = None
        if self._offscreen is not None:
            self._offscreen.close()
            self._offscreen = None
