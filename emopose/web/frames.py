"""Live image channels for the page: the simulation view and the camera feed, as JPEG.

One pump thread keeps each channel's latest frame fresh at its own rate, and only while at least
one page watches, so an idle server spends no CPU on rendering. Frames come from the PoseRenderer
(MuJoCo, its own thread) or an OpenCV webcam; clients pick the newest frame up by sequence number,
so a slow client skips frames instead of queueing them.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass

from emopose.execution.worker import Worker
from emopose.web.pose_renderer import encode_jpeg

log = logging.getLogger(__name__)


class Webcam:
    """A local camera through OpenCV, when OpenCV is installed and the device opens."""

    def __init__(self, capture) -> None:
        self._capture, self._lock = capture, threading.Lock()

    @classmethod
    def open(cls, index: int = 0) -> Webcam | None:
        try:
            import cv2
        except ImportError:
            return None
        capture = cv2.VideoCapture(index)
        if not capture.isOpened():
            capture.release()
            return None
        return cls(capture)

    def read_jpeg(self) -> bytes | None:
        with self._lock:
            ok, frame = self._capture.read()
        return encode_jpeg(frame[:, :, ::-1]) if ok else None  # OpenCV is BGR

    def close(self) -> None:
        with self._lock:
            self._capture.release()


@dataclass
class Channel:
    name: str  # "sim" | "camera": the one-byte tag of its binary WebSocket messages is name[0]
    fps: float
    produce: Callable[[], bytes | None]
    source: str = ""  # shown in the UI: "mujoco front", "webcam", "mujoco head"
    seq: int = 0
    jpeg: bytes | None = None
    error: str | None = None


class FramePump:
    def __init__(self, channels: list[Channel]) -> None:
        self.channels = {c.name: c for c in channels}
        self._viewers = 0
        self._lock = threading.Lock()
        self._worker = Worker("emopose-frames", self._run, join_timeout_s=5)

    @contextmanager
    def watching(self) -> Iterator[None]:
        with self._lock:
            self._viewers += 1
        try:
            yield
        finally:
            with self._lock:
                self._viewers -= 1

    def latest(self, name: str) -> tuple[int, bytes | None]:
        channel = self.channels[name]
        return channel.seq, channel.jpeg

    def start(self) -> None:
        if self.channels:
            self._worker.start()

    def stop(self) -> None:
        self._worker.stop()

    def _run(self, stop: threading.Event) -> None:
        due = {name: 0.0 for name in self.channels}
        while not stop.is_set():
            if self._viewers == 0:
                stop.wait(0.1)
                continue
            name = min(due, key=due.get)
            wait = due[name] - time.monotonic()
            if wait > 0:
                stop.wait(wait)
                continue
            channel = self.channels[name]
            try:
                jpeg = channel.produce()
                if jpeg is not None:
                    channel.jpeg, channel.seq, channel.error = jpeg, channel.seq + 1, None
            except Exception as exc:  # noqa: BLE001 -- one bad frame must not end the live view
                if channel.error is None:
                    log.warning("frame channel %s failed: %s", name, exc)
                channel.error = f"{type(exc).__name__}: {exc}"[:200]
            # Never schedule in the past: a slow renderer lowers the rate instead of bursting.
            due[name] = max(due[name] + 1.0 / channel.fps, time.monotonic())
