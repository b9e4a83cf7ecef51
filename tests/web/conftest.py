"""Fixtures for the web UI: a temporary copy of the shipped G1 library and a live served context.

Tests never write into library/g1: every config points library.paths / write_dir / limits at a copy.
"""

from __future__ import annotations

import copy
import functools
import shutil
import socket
from pathlib import Path

import pytest
from hydra import compose, initialize_config_dir
from omegaconf import OmegaConf

from emopose.config import CONFIG_DIR, PROJECT_ROOT

SHIPPED = PROJECT_ROOT / "library" / "g1"
LOCAL = "http://127.0.0.1"


@pytest.fixture
def library_copy(tmp_path: Path) -> Path:
    if not (SHIPPED / "neutral_rest.yaml").is_file():
        pytest.skip("library/g1 is not authored yet")
    target = tmp_path / "library" / "g1"
    shutil.copytree(SHIPPED, target, ignore=shutil.ignore_patterns(".backup"))
    return target


def library_overrides(folder: Path) -> list[str]:
    return [f"library.paths=[{folder}]", f"library.write_dir={folder}", f"library.limits={folder}/limits.yaml"]


@functools.lru_cache(maxsize=8)
def _composed(overrides: tuple[str, ...]):
    with initialize_config_dir(config_dir=str(CONFIG_DIR), version_base="1.3"):
        return compose("config", overrides=["+experiment=serve", "planner=keyword", "run.record=false",
                                             *overrides])


def compose_serve(folder: Path, *overrides: str):
    """Composing takes about a second; compose once per override set and point the copy at `folder`."""
    cfg = copy.deepcopy(_composed(tuple(overrides)))
    OmegaConf.update(cfg, "library.paths", [str(folder)])
    OmegaConf.update(cfg, "library.write_dir", str(folder))
    OmegaConf.update(cfg, "library.limits", str(folder / "limits.yaml"))
    return cfg


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def serve_app(library_copy, tmp_path):
    """A factory: serve_app(*overrides) -> (app, session, ctx), live (control loop running), no MuJoCo."""
    from emopose.build import build_context, build_job
    from emopose.web.app import create_app
    from emopose.web.live import open_session

    opened = []

    def make(*overrides: str):
        cfg = compose_serve(library_copy, *overrides)
        job = build_job(cfg)
        ctx = build_context(cfg, tmp_path / f"run{len(opened)}")
        session = open_session(ctx, job.settings, render=False)
        ctx.open()
        ctx.loop.start()
        opened.append((session, ctx))
        return create_app(session), session, ctx

    yield make
    for session, ctx in opened:
        session.close()
        ctx.close()


@pytest.fixture
def client(serve_app):
    from fastapi.testclient import TestClient

    app, _, _ = serve_app()
    with TestClient(app, base_url=LOCAL) as test_client:
        yield test_client
