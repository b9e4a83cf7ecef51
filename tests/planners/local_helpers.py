"""The configured local planner (same training files and cache as the app) on a writable library copy,
and its training settings."""

from __future__ import annotations

import shutil
from pathlib import Path

from emopose.config import PROJECT_ROOT
from emopose.library import MotionLibrary


def training_config(**changes):
    """conf/planner/local.yaml's training settings (the one place they live), with changes."""
    from omegaconf import OmegaConf

    from emopose.planners.local.config import TrainingConfig
    from tests.conftest import compose_config

    return TrainingConfig(**{**OmegaConf.to_container(compose_config(["planner=local"]).planner.training,
                                                      resolve=True), **changes})


def configured_local_planner(folder: Path, *overrides: str):
    from emopose.build import make
    from tests.conftest import compose_config  # the compose fixture is per test; callers are per module

    shutil.copytree(PROJECT_ROOT / "library/g1", folder)
    library = MotionLibrary.from_config(paths=[str(folder)], limits=str(folder / "limits.yaml"),
                                        write_dir=str(folder))
    return make(compose_config(["planner=local", *overrides]).planner, "planner", library=library)
