"""Run one composed config: build the resources, session, runner and job, run it, always release the robot."""

from __future__ import annotations

import logging
from pathlib import Path

from omegaconf import DictConfig

from emopose.build import build_job, build_run

log = logging.getLogger(__name__)


def run(cfg: DictConfig, run_dir: str | Path) -> dict:
    run_dir = Path(run_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    job = build_job(cfg)
    with build_run(cfg, run_dir) as built:
        return job(built)
