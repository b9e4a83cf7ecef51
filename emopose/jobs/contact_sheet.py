"""Contact sheets: a motion's keyframes rendered in MuJoCo, labelled, one PNG per motion + an overview.

Keyframes are posed kinematically (backend.reset), so a sheet shows what the library author wrote;
the library check adds the simulated pose at the first self-contact as an extra, red-labelled column.
"""

from __future__ import annotations

import math
import textwrap
from pathlib import Path

import numpy as np

from emopose import CONTROL_DT

# Free cameras framing the upper body (the model's own cameras show the whole robot, too small for
# judging a hand pose): azimuth 180 looks at the robot's front (it faces +x); 220 is from its left.
VIEWS = {
    "front": {"azimuth": 180.0, "elevation": -8.0},
    "oblique": {"azimuth": 220.0, "elevation": -15.0},
    "side": {"azimuth": 270.0, "elevation": -5.0},
}
LOOKAT, DISTANCE = (0.0, 0.0, 1.08), 1.5  # frames hands from the hips to above the head


def view(name: str):
    """A mujoco.MjvCamera for a VIEWS preset; any other name is a camera defined in the MJCF."""
    if name not in VIEWS:
        return name
    import mujoco

    camera = mujoco.MjvCamera()
    camera.type = mujoco.mjtCamera.mjCAMERA_FREE
    camera.lookat[:] = LOOKAT
    camera.distance = DISTANCE
    camera.azimuth, camera.elevation = VIEWS[name]["azimuth"], VIEWS[name]["elevation"]
    return camera


def render_pose(backend, q: np.ndarray, cameras: list[str]) -> list[np.ndarray]:
    """Images of the pose q held at rest, one per camera."""
    backend.reset(q)
    return [backend.render_frame(view(c)) for c in cameras]


def render_keyframes(backend, keyframes: np.ndarray, cameras: list[str]) -> list[list[np.ndarray]]:
    """[keyframe][camera] -> (H, W, 3) image of each keyframe posed at rest."""
    return [render_pose(backend, q, cameras) for q in np.atleast_2d(keyframes)]


def peak_index(keyframes: np.ndarray) -> int:
    """The keyframe farthest from the first: the pose that best shows what the motion is."""
    q = np.atleast_2d(keyframes)
    return int(np.argmax(np.abs(q - q[0]).max(axis=1)))


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")  # files only; never open a window
    import matplotlib.pyplot as plt

    return plt


def write_sheet(folder: Path, entry, frames: list[list[np.ndarray]], extra: tuple | None,
                status: str) -> Path:
    """One PNG: rows = cameras, columns = keyframes (+ the contact pose), titled with name and status."""
    plt = _pyplot()
    columns = list(frames) + ([extra[0]] if extra else [])
    rows = len(columns[0])
    height, width = columns[0][0].shape[:2]
    scale = 2.0 / width * 100
    fig, axes = plt.subplots(rows, len(columns), squeeze=False,
                             figsize=(len(columns) * width * scale / 100, rows * height * scale / 100 + 0.8))
    times = _keyframe_times(len(frames), entry.default_duration)
    for c, column in enumerate(columns):
        is_extra = extra is not None and c == len(columns) - 1
        for r, image in enumerate(column):
            ax = axes[r][c]
            ax.imshow(image)
            ax.set_xticks([]), ax.set_yticks([])
            if r == 0:
                label = extra[1] if is_extra else f"k={c}  t={times[c]:.2f}s"
                ax.set_title(label, fontsize=7, color="red" if is_extra else "black")
    color = "black" if status == "ok" else "red"
    title = textwrap.fill(f"{entry.name} ({entry.cls}) - {entry.description}", width=24 * len(columns))
    fig.suptitle(f"{title}\nlevel 3 keyframes, d={entry.default_duration:.2f}s | {status}", fontsize=8,
                 color=color)
    fig.tight_layout()
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{entry.name}.png"
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def _keyframe_times(count: int, duration: float) -> list[float]:
    """Keyframe k is reached at k d / (K - 1) (uniform segments, Eq. smoothstep), snapped to ticks."""
    if count == 1:
        return [duration]
    return [round(k * duration / (count - 1) / CONTROL_DT) * CONTROL_DT for k in range(count)]


def write_overview(path: Path, library, frames: dict[str, list[list[np.ndarray]]],
                   status: dict[str, str]) -> Path:
    """Every motion's peak keyframe (first camera) in one grid, ordered by class; red title = contacts."""
    plt = _pyplot()
    from emopose import CLASSES

    names = sorted(frames, key=lambda n: (CLASSES.index(library.get(n).cls), n))
    cols = max(1, math.ceil(math.sqrt(len(names) * 1.4)))
    rows = math.ceil(len(names) / cols)
    fig, axes = plt.subplots(rows, cols, squeeze=False, figsize=(cols * 2.0, rows * 1.75))
    for ax in axes.flat:
        ax.axis("off")
    for ax, name in zip(axes.flat, names):
        entry = library.get(name)
        ax.imshow(frames[name][peak_index(entry.q)][0])
        ok = status.get(name, "ok") == "ok"
        ax.set_title(f"{name}\n{entry.cls}" + ("" if ok else f" - {status[name]}"), fontsize=6,
                     color="black" if ok else "red")
    fig.suptitle("Motion library: peak keyframe per motion (level 3, front)", fontsize=9)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
