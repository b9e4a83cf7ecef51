"""The tour video: tour.mp4 (H.264, AAC when the tour spoke with TTS audio) and tour.vtt, made from the
session recording after the tour, in a child process: no frame is rendered in the process that ran the
control loop, and the tour itself runs as fast without a video as with one.

A camera follows the robot at its chest (three-quarter front by default, `azimuth_deg`), so gestures are
seen at the size they are judged at. The spoken sentence is burned into the bottom of each frame (any
player shows it) and also written as WebVTT captions beside the video. Frames are piped to the ffmpeg
that imageio-ffmpeg ships; software GL renders about 10 frames a second at 640x480 on one core.
"""

from __future__ import annotations

import logging
import os
import subprocess
import tempfile
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from emopose.child_process import ChildProcess, serve_requests
from emopose.tour.video_track import Cue, audio_track, caption_cues, read_track, webvtt

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class VideoSettings:
    width: int = 640
    height: int = 480
    fps: float = 15.0
    distance_m: float = 3.0  # from the camera to the robot's chest
    elevation_deg: float = -12.0  # below zero: looking down on the robot
    azimuth_deg: float = 150.0  # around the robot from behind it: 180 faces it, 150 a three-quarter view
    caption_px: int = 20  # caption text height

    def __post_init__(self) -> None:
        if self.width < 64 or self.height < 64 or self.width % 2 or self.height % 2:
            raise ValueError(f"video size must be even and at least 64x64, got {self.width}x{self.height}")
        if not 1 <= self.fps <= 60:
            raise ValueError(f"video fps must be within 1..60, got {self.fps}")


def make_video(recording: str | Path, scene: str | Path, out: str | Path,
               settings: VideoSettings = VideoSettings()) -> Path:
    """Render the recorded tour into `out` (and its .vtt) in a child process; its error is raised here."""
    child = ChildProcess("emopose.tour.video", "serve_video", name="video renderer")
    try:
        child.receive()  # the child has started
        return child.request((str(recording), str(scene), str(out), asdict(settings)))
    finally:
        child.close()


def serve_video() -> None:
    """The render process (started by make_video)."""
    serve_requests(lambda: _write_video)


def _write_video(job: tuple[str, str, str, dict]) -> Path:
    recording, scene, out = (Path(p) for p in job[:3])
    settings = VideoSettings(**job[3])
    track = read_track(recording)
    cues = caption_cues(track.said)
    out.with_suffix(".vtt").write_text(webvtt(cues))
    frames, captions = _Frames(scene, settings), _Captions(settings)
    with tempfile.TemporaryDirectory() as tmp:
        sound = audio_track(track.chunks, track.end_s)
        wav = None if sound is None else _write_wav(Path(tmp) / "speech.wav", *sound)
        errors = Path(tmp) / "ffmpeg.log"
        with errors.open("wb") as log_file:
            ffmpeg = subprocess.Popen(_ffmpeg_command(out, settings, wav), stdin=subprocess.PIPE,
                                      stdout=subprocess.DEVNULL, stderr=log_file)
            for k in range(int(track.end_s * settings.fps) + 1):
                t = k / settings.fps
                image = captions.draw(frames.render(*track.pose_at(t)), _cue_at(cues, t))
                ffmpeg.stdin.write(image.tobytes())
            ffmpeg.stdin.close()
            code = ffmpeg.wait()
        if code != 0:
            raise RuntimeError(f"ffmpeg failed ({code}): {errors.read_text(errors='replace').strip()[-300:]}")
    return out


def _ffmpeg_command(out: Path, settings: VideoSettings, wav: Path | None) -> list[str]:
    import imageio_ffmpeg

    frames = ["-f", "rawvideo", "-pix_fmt", "rgb24", "-s", f"{settings.width}x{settings.height}",
              "-r", f"{settings.fps:g}", "-i", "-"]
    audio = [] if wav is None else ["-i", str(wav), "-map", "0:v", "-map", "1:a", "-c:a", "aac",
                                    "-b:a", "96k"]
    return [imageio_ffmpeg.get_ffmpeg_exe(), "-y", "-loglevel", "error", *frames, *audio,
            "-c:v", "libx264", "-preset", "veryfast", "-pix_fmt", "yuv420p", str(out)]


def _write_wav(path: Path, rate: int, samples: np.ndarray) -> Path:
    from emopose.speech.wav import write_wav

    return write_wav(path, samples.astype("<i2").tobytes(), rate)


def _cue_at(cues: list[Cue], t: float) -> str:
    return next((c.text for c in cues if c.start_s <= t < c.end_s), "")


class _Frames:
    """In the render process: the tour scene with its planar base, and a camera that follows the robot."""

    def __init__(self, scene: Path, settings: VideoSettings) -> None:
        os.environ.setdefault("MUJOCO_GL", "egl")
        import mujoco

        from emopose.robot.g1_spec import JOINT_NAMES
        from emopose.robot.model import BASE_JOINTS, build_model

        self.mujoco, self.settings = mujoco, settings
        self.model = build_model(scene, planar_base=True)  # as the backend loaded it
        self.model.vis.quality.offsamples = 0  # no multisampling: a third of the software render time
        for geom in range(self.model.ngeom):  # an exhibit between the camera and the robot hides nothing
            if self.model.geom(geom).name.startswith(("object_", "post_")):
                self.model.geom_rgba[geom, 3] = 0.5
        self.data = mujoco.MjData(self.model)
        self.base_adr = [self.model.joint(n).qposadr[0] for n in BASE_JOINTS]
        self.arm_adr = [self.model.joint(n).qposadr[0] for n in JOINT_NAMES]
        self.renderer = mujoco.Renderer(self.model, settings.height, settings.width)
        self.camera = mujoco.MjvCamera()
        self.camera.type = mujoco.mjtCamera.mjCAMERA_FREE
        self.camera.distance, self.camera.elevation = settings.distance_m, settings.elevation_deg

    def render(self, base: np.ndarray, arms: np.ndarray) -> np.ndarray:
        self.data.qpos[self.base_adr], self.data.qpos[self.arm_adr] = base, arms
        self.mujoco.mj_forward(self.model, self.data)
        self.camera.lookat[:] = self.data.body("pelvis").xpos + [0.0, 0.0, 0.1]  # the robot high in the frame
        self.camera.azimuth = np.degrees(base[2]) + self.settings.azimuth_deg
        self.renderer.update_scene(self.data, camera=self.camera)
        return self.renderer.render()


class _Captions:
    """The sentence being said, white on a darkened band at the bottom of the frame, wrapped to fit."""

    def __init__(self, settings: VideoSettings) -> None:
        from PIL import ImageFont

        self.font = ImageFont.load_default(settings.caption_px)
        self.line_px, self.margin = int(settings.caption_px * 1.3), settings.caption_px

    def draw(self, frame: np.ndarray, text: str) -> np.ndarray:
        if not text:
            return frame
        from PIL import Image, ImageDraw

        image = Image.fromarray(frame)
        canvas = ImageDraw.Draw(image)
        lines = self._wrap(canvas, text, image.width - 2 * self.margin)
        top = image.height - self.margin // 2 - self.line_px * len(lines)
        shaded = np.asarray(image).copy()
        shaded[top - self.margin // 2:] = shaded[top - self.margin // 2:] // 3
        image = Image.fromarray(shaded)
        canvas = ImageDraw.Draw(image)
        for row, line in enumerate(lines):
            width = canvas.textlength(line, font=self.font)
            canvas.text(((image.width - width) / 2, top + row * self.line_px), line, font=self.font,
                        fill=(255, 255, 255))
        return np.asarray(image)

    def _wrap(self, canvas, text: str, width: float) -> list[str]:
        lines: list[str] = []
        for word in text.split():
            if lines and canvas.textlength(f"{lines[-1]} {word}", font=self.font) <= width:
                lines[-1] = f"{lines[-1]} {word}"
            else:
                lines.append(word)
        return lines
