"""The one place that calls hydra.utils.instantiate: composed config -> run context and job.

Shared resources (library, planner, backend, clock, speech) are built once here and travel in the
RunContext; stages and planners receive plain typed arguments, never a DictConfig.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from hydra.errors import InstantiationException
from hydra.utils import instantiate
from omegaconf import DictConfig, OmegaConf

from emopose.clock import FakeClock, MonotonicClock
from emopose.context import RunContext
from emopose.library import MotionLibrary
from emopose.pipeline import Pipeline
from emopose.trajectory import TrajectoryBuilder


class ConfigError(ValueError):
    """A config value cannot be built; the message names the config key."""


def make(node: Any, key: str, **kwargs: Any) -> Any:
    """instantiate() with the config key named in any error; an empty or null node builds nothing."""
    if node is None or (isinstance(node, DictConfig) and "_target_" not in node):
        return None
    try:
        if not kwargs:
            return instantiate(node, _convert_="all")
        # Runtime objects go straight to the factory: instantiate(node, **kwargs) would merge them into the
        # config, and OmegaConf turns a dataclass instance (MotionLibrary, TrajectoryBuilder) into a config node.
        factory = instantiate(node, _convert_="all", _partial_=True)
        return factory(**kwargs)
    except (InstantiationException, TypeError, ValueError) as exc:  # a bad value the target rejected
        cause = exc.__cause__ or exc
        raise ConfigError(f"cannot build '{key}' ({OmegaConf.select(node, '_target_')}): {cause}") from exc


def safety_check(checker: Any):
    """Adapt a SelfCollisionChecker to the sequencer's `samples -> reason | None` hook."""
    if checker is None:
        return None

    def check(samples):
        report = checker.check(samples)
        return None if report.ok else report.reason

    return check


def check_planner(planner: Any) -> None:
    """Planners that call a service say what is missing (key, model string) before any run starts."""
    check = getattr(planner, "check", None)
    if check is None:
        return
    try:
        check()
    except ValueError as exc:
        raise ConfigError(f"planner: {exc}") from exc


def build_context(cfg: DictConfig, run_dir: str | Path) -> RunContext:
    library: MotionLibrary = make(cfg.library, "library")
    planner = make(cfg.planner, "planner", library=library)
    check_planner(planner)
    stages = {name: make(node, f"pipeline.stages.{name}") for name, node in cfg.pipeline.stages.items()}
    backend = make(cfg.backend, "backend")
    realtime = cfg.run.clock == "monotonic" or (cfg.run.clock == "auto" and getattr(backend, "realtime", False))
    clock = MonotonicClock() if realtime else FakeClock()
    builder = TrajectoryBuilder(library.limits)
    sequencer = make(cfg.sequencer, "sequencer", builder=builder, neutral=library.neutral_entry.q[0],
                     safety=safety_check(make(cfg.safety, "safety")))
    speech = make(cfg.tts, "tts")
    player = make(cfg.get("player"), "player")
    thinking = make(cfg.get("thinking"), "thinking", library=library)
    return RunContext(library=library, planner=planner, pipeline=Pipeline(stages), backend=backend,
                      sequencer=sequencer, clock=clock, speech=speech, player=player, thinking=thinking,
                      run_dir=Path(run_dir), record=bool(cfg.run.record))


def build_job(cfg: DictConfig) -> Any:
    if "job" not in cfg or cfg.job is None:
        raise ConfigError("no job configured: pick one with +experiment=NAME (see conf/experiment/)")
    return make(cfg.job, "job")
