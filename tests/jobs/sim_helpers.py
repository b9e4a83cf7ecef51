"""Helpers for the simulation jobs: compose a config, and tell whether offscreen rendering works here."""

from __future__ import annotations

import os

# re-exported for tests/jobs, tests/tour
from tests.conftest import compose_config, synthetic_library  # noqa: F401

os.environ.setdefault("MUJOCO_GL", "egl")  # before the first mujoco import


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
SMALL_FRAMES = ["backend.renderer.width=96", "backend.renderer.height=72"]
