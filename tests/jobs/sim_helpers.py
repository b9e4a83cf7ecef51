"""Helpers for the simulation jobs: compose a config, and tell whether offscreen rendering works here."""

from __future__ import annotations

import os

from hydra import compose, initialize_config_dir

from emopose.config import CONFIG_DIR
from tests.conftest import make_library_dir

os.environ.setdefault("MUJOCO_GL", "egl")  # before the first mujoco import


def compose_config(overrides: list[str]):
    with initialize_config_dir(config_dir=str(CONFIG_DIR), version_base="1.3"):
        return compose("config", overrides=overrides)


def _render_skip_reason() -> str | None:
    try:
        import mujoco

        renderer = mujoco.Renderer(mujoco.MjModel.from_xml_string("<mujoco/>"), 8, 8)
        renderer.close()
    except Exception as exc:  # noqa: BLE001 -- no EGL/OSMesa here: the image parts are skipped
        return f"offscreen rendering unavailable (MUJOCO_GL={os.environ.get('MUJOCO_GL')}): {exc}"
    return None


RENDER_SKIP = _render_skip_reason()


# Small frames keep rendering tests quick.
SMALL_FRAMES = ["backend.width=96", "backend.height=72"]


def synthetic_library(folder) -> list[str]:
    """Overrides that swap in the small synthetic test library (tests/conftest.py) written to folder."""
    make_library_dir(folder)
    return [f"library.paths=[{folder}]", f"library.limits={folder}/limits.yaml", "library.write_dir=null",
            "~library.class_defaults"]
