"""Shared fixtures: the repo's config composed through Hydra, and a small synthetic motion library
(independent of the authored G1 set)."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable
from pathlib import Path

import numpy as np
import pytest
import yaml
from hydra import compose as hydra_compose
from hydra import initialize_config_dir
from omegaconf import DictConfig

os.environ.setdefault("MUJOCO_GL", "egl")
os.environ.setdefault("HF_HUB_OFFLINE", "1")
os.environ.setdefault("HYDRA_FULL_ERROR", "1")

from emopose import CLASSES  # noqa: E402
from emopose.config import CONFIG_DIR, project_path  # noqa: E402
from emopose.library import MotionLibrary  # noqa: E402

LOWER = [-3.0892, -1.5882, -2.618, -1.0472, -1.97222, -1.61443, -1.61443,
         -3.0892, -2.2515, -2.618, -1.0472, -1.97222, -1.61443, -1.61443]
UPPER = [2.6704, 2.2515, 2.618, 2.0944, 1.97222, 1.61443, 1.61443,
         2.6704, 1.5882, 2.618, 2.0944, 1.97222, 1.61443, 1.61443]
NAMES = [f"{side}_{j}_joint" for side in ("left", "right") for j in
         ("shoulder_pitch", "shoulder_roll", "shoulder_yaw", "elbow", "wrist_roll", "wrist_pitch",
          "wrist_yaw")]
REST = [0.2, 0.2, 0.0, 0.3, 0.0, 0.0, 0.0, 0.2, -0.2, 0.0, 0.3, 0.0, 0.0, 0.0]


def compose_config(overrides: Iterable[str] = ()) -> DictConfig:
    """conf/config.yaml composed with command-line style overrides, as `python -m emopose` would."""
    with initialize_config_dir(config_dir=str(CONFIG_DIR), version_base="1.3"):
        return hydra_compose("config", overrides=list(overrides))


@pytest.fixture
def compose() -> Callable[..., DictConfig]:
    """compose("+experiment=plan", "planner=keyword") -> the composed config."""
    return lambda *overrides: compose_config(overrides)


def write_motion(folder: Path, name: str, cls: str, keyframes, **extra) -> Path:
    data = {"name": name, "class": cls, "description": f"{name.replace('_', ' ')} test motion",
            "keyframes": [list(map(float, k)) for k in keyframes], **extra}
    path = folder / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def raised(amount: float, joint: int) -> list[float]:
    q = list(REST)
    q[joint] += amount
    return q


def make_library_dir(folder: Path) -> Path:
    folder.mkdir(parents=True)
    (folder / "limits.yaml").write_text(yaml.safe_dump(
        {"joints": NAMES, "lower": LOWER, "upper": UPPER, "max_velocity": 8.0}))
    write_motion(folder, "neutral_rest", "neutral", [REST], motion_type="pose")
    for cls in CLASSES:
        if cls == "neutral":
            write_motion(folder, "idle_breathe", "neutral", [REST, raised(0.1, 3), REST])
            continue
        write_motion(folder, f"{cls}_a", cls, [REST, raised(-0.6, 7), raised(-0.9, 7), REST])
        write_motion(folder, f"{cls}_b", cls, [REST, raised(0.5, 10), REST], duration=1.5)
    return folder


def synthetic_library(folder: Path) -> list[str]:
    """Write the synthetic library to folder; overrides that make a composed config load it."""
    make_library_dir(folder)
    return [f"library.paths=[{folder}]", f"library.limits={folder}/limits.yaml", "library.write_dir=null",
            "~library.class_defaults"]


def load_library(folder: Path) -> MotionLibrary:
    return MotionLibrary.from_config(paths=[str(folder)], limits=str(folder / "limits.yaml"),
                                     neutral="neutral_rest", write_dir=str(folder))


@pytest.fixture(scope="session")
def library(tmp_path_factory) -> MotionLibrary:
    """Read-only shared library; tests that save motions use `writable_library`."""
    return load_library(make_library_dir(tmp_path_factory.mktemp("lib") / "library"))


@pytest.fixture(scope="session")
def g1() -> MotionLibrary:
    """The shipped G1 library (timing tests need its real strokes, durations and speed bounds)."""
    return MotionLibrary.from_config(paths=[str(project_path("library/g1"))],
                                     limits=str(project_path("library/g1/limits.yaml")))


@pytest.fixture
def writable_library(tmp_path: Path) -> MotionLibrary:
    return load_library(make_library_dir(tmp_path / "library"))


@pytest.fixture
def rest() -> np.ndarray:
    return np.array(REST)
