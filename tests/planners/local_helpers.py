"""The configured local planner (same training files and cache as the app) on a writable library copy."""

from __future__ import annotations

import shutil
from pathlib import Path

from emopose.config import PROJECT_ROOT
from emopose.library import MotionLibrary


def configured_local_planner(folder: Path, *overrides: str):
    from emopose.build import make
    from tests.conftest import compose_config  # the compose fixture is per test; callers are per module

    shutil.copytree(PROJECT_ROOT / "library/g1", folder)
    library = MotionLibrary.from_config(paths=[str(folder)], limits=str(folder / "limits.yaml"),
                                        write_dir=str(folder))
    return make(compose_config(["planner=local", *overrides]).planner, "planner", library=library)
