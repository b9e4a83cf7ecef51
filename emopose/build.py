"""The one place that calls hydra.utils.instantiate: composed config -> resources, session, runner, job.

Shared resources (library, planner, backend, clock, synthesizer, sequencer, control loop, ...) are built
once here. A stage receives the ones it needs through its constructor: every constructor parameter
whose name is a resource (`library`, `limits`, `synthesizer`, `sequencer`, `clock`, `loop`, `player`,
`scene`, `safety`) is passed that resource, so adding a stage needs one YAML node and one class, and
its dependencies are visible in its signature.
"""

from __future__ import annotations

import inspect
from pathlib import Path
from typing import Any

from hydra.errors import InstantiationException
from hydra.utils import get_object, instantiate
from omegaconf import DictConfig, OmegaConf

from emopose.clock import clock_for
from emopose.execution.control_loop import ControlLoop
from emopose.execution.trajectory import TrajectoryBuilder
from emopose.planners.base import CheckedPlanner, Planner
from emopose.resources import Resources, Run
from emopose.scene.view import SceneSlot
from emopose.speech.audio_channel import SpeechRecording
from emopose.speech.player import Player
from emopose.turn.pipeline import Pipeline, PipelineError
from emopose.turn.runner import TurnRunner
from emopose.turn.session import Session


class ConfigError(ValueError):
    """A config value cannot be built; the message names the config key."""


def make(node: Any, key: str, **kwargs: Any) -> Any:
    """instantiate() with the config key named in any error; an empty or null node builds nothing."""
    if node is None or (isinstance(node, DictConfig) and "_target_" not in node):
        return None
    try:
        if not kwargs:
            return instantiate(node, _convert_="all")
        # Runtime objects go straight to the factory: instantiate(node, **kwargs) would merge them into
        # the config, and OmegaConf turns a dataclass (MotionLibrary, TrajectoryBuilder) into a config node.
        factory = instantiate(node, _convert_="all", _partial_=True)
        return factory(**kwargs)
    except (InstantiationException, TypeError, ValueError) as exc:  # a bad value the target rejected
        cause = exc.__cause__ or exc
        raise ConfigError(f"cannot build '{key}' ({OmegaConf.select(node, '_target_')}): {cause}") from exc


def make_with(node: Any, key: str, resources: dict[str, Any]) -> Any:
    """make() passing each resource the target's constructor asks for by name."""
    if node is None or "_target_" not in node:
        return None
    try:
        wanted = inspect.signature(get_object(node._target_)).parameters
    except Exception as exc:  # an unknown or unimportable _target_
        raise ConfigError(f"cannot build '{key}': {exc}") from exc
    return make(node, key, **{name: value for name, value in resources.items() if name in wanted})


def ordered_stages(pipeline: DictConfig) -> dict[str, Any]:
    """The stage nodes in `pipeline.order`, each `pipeline.insert_after` stage placed after its anchor."""
    order = list(pipeline.order)
    for name, anchor in (pipeline.get("insert_after") or {}).items():
        if anchor not in order:
            raise ConfigError(f"pipeline.insert_after.{name}: no stage {anchor!r} in the order {order}")
        order.insert(order.index(anchor) + 1, name)
    unplaced = [name for name in pipeline.stages if name not in order]
    missing = [name for name in order if name not in pipeline.stages]
    if unplaced or missing:
        raise ConfigError(f"pipeline: stages {unplaced} have no place in the order (add them to "
                          f"pipeline.insert_after) and {missing} in the order have no stage node")
    return {name: pipeline.stages[name] for name in order}


def safety_check(checker: Any):
    """Adapt a SelfCollisionChecker to the sequencer's `samples -> reason | None` hook."""
    if checker is None:
        return None

    def check(samples):
        report = checker.check(samples)
        return None if report.ok else report.reason

    return check


def check_planner(planner: Planner) -> None:
    """Planners that call a service say what is missing (key, model string) before any run starts."""
    if not isinstance(planner, CheckedPlanner):
        return
    try:
        planner.check()
    except ValueError as exc:
        raise ConfigError(f"planner: {exc}") from exc


def build_run(cfg: DictConfig, run_dir: str | Path) -> Run:
    make(cfg.get("arm_law"), "arm_law")  # the law validates itself, whichever backend (if any) applies it
    library = make(cfg.library, "library")
    planner = make_with(cfg.planner, "planner", {"library": library})
    check_planner(planner)
    backend = make(cfg.backend, "backend")
    try:
        clock = clock_for(cfg.run.clock, backend.realtime)
    except ValueError as exc:
        raise ConfigError(str(exc)) from exc
    safety = safety_check(make(cfg.safety, "safety"))
    sequencer = make(cfg.sequencer, "sequencer", builder=TrajectoryBuilder(library.limits),
                     neutral=library.neutral_entry.q[0], safety=safety)
    loop = ControlLoop(sequencer, backend, clock)
    player = make(cfg.get("player"), "player") or Player(sink="none")
    synthesizer, scene = make(cfg.tts, "tts"), SceneSlot()
    shared = {"library": library, "limits": library.limits, "synthesizer": synthesizer,
              "sequencer": sequencer, "clock": clock, "loop": loop, "player": player, "scene": scene,
              "safety": safety}
    stages = {name: make_with(node, f"pipeline.stages.{name}", shared)
              for name, node in ordered_stages(cfg.pipeline).items()}
    try:
        pipeline = Pipeline(stages)
    except PipelineError as exc:  # a mis-ordered or ablated pipeline: refused before any model call
        raise ConfigError(f"pipeline: {exc}") from exc
    resources = Resources(library=library, planner=planner, pipeline=pipeline, backend=backend,
                          sequencer=sequencer, clock=clock, synthesizer=synthesizer, player=player,
                          asr=make(cfg.get("asr"), "asr"), scene=scene, run_dir=Path(run_dir))
    session = Session(backend, loop, library.neutral_entry.q[0], run_dir, record=bool(cfg.run.record))
    sequencer.on_event = session.record_event
    player.on_play = SpeechRecording(session.record_at)  # what was said and heard, in the recording
    thinking = make_with(cfg.get("thinking"), "thinking", shared)
    return Run(resources, session, TurnRunner(planner, pipeline, session, thinking))


def build_job(cfg: DictConfig) -> Any:
    if "job" not in cfg or cfg.job is None:
        raise ConfigError("no job configured: pick one with +experiment=NAME (see conf/experiment/)")
    return make(cfg.job, "job")
