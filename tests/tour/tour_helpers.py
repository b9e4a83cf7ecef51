"""Helpers for the tour tests: a small two-stop scenario and a way to run a tour and look inside it."""

from __future__ import annotations

import copy
import os
from contextlib import contextmanager
from pathlib import Path

import yaml

os.environ.setdefault("MUJOCO_GL", "egl")  # before the first mujoco import

from emopose.build import build_run
from emopose.config import CONFIG_DIR
from emopose.tour.camera import camera_for
from emopose.tour.runner import TourRunner
from emopose.tour.scenario_loading import parse_tour
from emopose.tour.sim_base import MujocoBase
from emopose.tour.sim_scene import install_scene
from tests.jobs.sim_helpers import RENDER_SKIP, compose_config, synthetic_library  # noqa: F401

LAB_FILE = CONFIG_DIR / "tour" / "lab.yaml"

SMALL = {
    "name": "small",
    "arena": {"x": [-1.0, 3.0], "y": [-2.0, 2.5]},
    "stops": [
        {"name": "first", "pose": {"x": 0.6, "y": 0.0, "yaw_deg": 0.0},
         "narration": "Hello and welcome to the lab! Look at the red box over there. "
                      "It is really important to us.",
         "objects": [{"name": "red_box", "position": [1.8, -0.5, 1.0], "aliases": ["box", "red box"],
                      "color": [0.9, 0.1, 0.1]}]},
        {"name": "second", "pose": {"x": 0.6, "y": 0.8, "yaw_deg": 90.0},
         "approach": "Please look at the next stop over there, it is very important.",
         "narration": "This is the second stop. See the blue ball on your left. We are nearly done now.",
         "objects": [{"name": "blue_ball", "position": [-0.2, 2.0, 1.2], "aliases": ["ball", "blue ball"],
                      "color": [0.1, 0.2, 0.9]}]},
    ],
}


def small(**changes) -> dict:
    raw = copy.deepcopy(SMALL)
    raw.update(changes)
    return raw


def lab_raw() -> dict:
    return yaml.safe_load(LAB_FILE.read_text())


def tour_config(tmp_path: Path, *overrides: str):
    """+experiment=tour_lab on the synthetic test library, without a video."""
    return compose_config(["+experiment=tour_lab", *synthetic_library(tmp_path / "lib"), "job.video=false",
                           *overrides])


@contextmanager
def tour_runner(tmp_path: Path, raw: dict, *overrides: str):
    """A fresh simulated run and a TourRunner in it, as (run, tour); the run is closed afterwards."""
    with build_run(tour_config(tmp_path, *overrides), tmp_path) as run:
        spec, backend = parse_tour(raw, "test scenario"), run.resources.backend
        install_scene(backend, spec, tmp_path)
        run.session.open()
        base = MujocoBase(backend.planar_base)  # noiseless odometry
        base.place(spec.start.pose())
        yield run, TourRunner(run, spec, base, camera_for(backend))
