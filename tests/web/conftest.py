"""Fixtures for the web UI: a temporary copy of the shipped G1 library, a live served Run, a Chromium.

Tests never write into library/g1: every config points library.paths / write_dir / limits at a copy.
"""

from __future__ import annotations

import copy
import functools
import shutil
import socket
from pathlib import Path

import pytest
from omegaconf import OmegaConf

from emopose.config import PROJECT_ROOT
from tests.conftest import compose_config

SHIPPED = PROJECT_ROOT / "library" / "g1"
LOCAL = "http://127.0.0.1"


def copy_library(root: Path) -> Path:
    """library/g1 copied to root/library/g1 (without its backups)."""
    assert (SHIPPED / "neutral_rest.yaml").is_file(), (f"{SHIPPED} lacks neutral_rest.yaml: "
                                                       "the shipped library broke")
    target = root / "library" / "g1"
    shutil.copytree(SHIPPED, target, ignore=shutil.ignore_patterns(".backup"))
    return target


@pytest.fixture
def library_copy(tmp_path: Path) -> Path:
    return copy_library(tmp_path)


def library_overrides(folder: Path) -> list[str]:
    return [f"library.paths=[{folder}]", f"library.write_dir={folder}",
            f"library.limits={folder}/limits.yaml"]


@functools.lru_cache(maxsize=8)
def _composed(overrides: tuple[str, ...]):
    return compose_config(["+experiment=serve", "planner=keyword", "run.record=false", *overrides])


def compose_serve(folder: Path, *overrides: str):
    """Composing takes a while; compose once per override set and point the copy at `folder`."""
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
    """A factory: serve_app(*overrides) -> (app, session), built as ServeJob builds it from the composed
    serve experiment, live (control loop running), without MuJoCo frames. The Run is `session.run`."""
    from emopose.build import build_job, build_run
    from emopose.web.app import create_app
    from emopose.web.live import open_session

    opened = []

    def make(*overrides: str):
        cfg = compose_serve(library_copy, *overrides)
        settings = build_job(cfg).settings  # validated first, as the CLI does: a bad serve.* builds nothing
        run = build_run(cfg, tmp_path / f"run{len(opened)}")
        session = open_session(run, settings, render=False)
        opened.append(session)
        run.session.open().start()
        return create_app(session), session

    yield make
    for session in opened:
        session.close()
        session.run.session.close()


@pytest.fixture
def client(serve_app):
    from fastapi.testclient import TestClient

    app, _ = serve_app()
    with TestClient(app, base_url=LOCAL) as test_client:
        yield test_client


@pytest.fixture(scope="session")
def browser():
    """Debian's Chromium under Playwright (the browser tests are marked slow)."""
    from tests.web.browser import chromium

    with chromium() as launched:
        yield launched
