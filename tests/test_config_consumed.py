"""Every config group in conf/config.yaml's defaults is consumed: build_run puts its object in the Run.

A group can compose and yet be dead: `asr` was, until build.py built it (asr=litellm composed, and the web
UI still offered no microphone). The groups come from config.yaml's defaults list, so a group added there
fails this test until the build consumes it and CONSUMERS says where its object lives in the Run. Every
option of every group is built, so a build that ignored the choice (a hard-coded default) fails as well.
"""

from __future__ import annotations

from pathlib import Path
from typing import get_type_hints

import numpy as np
import pytest
from hydra.utils import get_object
from omegaconf import DictConfig, OmegaConf

from emopose.build import build_run, ordered_stages
from emopose.config import CONFIG_DIR
from emopose.planners.chat.prompting import load_demonstrations
from tests.conftest import compose_config

DEFAULTS = {group: option for entry in OmegaConf.load(CONFIG_DIR / "config.yaml").defaults
            if isinstance(entry, DictConfig) for group, option in entry.items()}
UNBUILDABLE = {("planner", "local"): "trains for minutes on first use (tests/planners/test_local.py)",
               ("planner", "annotate"): "its annotator is planner=local (tests/planners/test_annotate.py)"}
# read by some options of another group
CONSUMED_WITH = {"prompt": ["planner=llm"], "arm_law": ["backend=mujoco"]}


def built_from(node: DictConfig, obj, *settings: str) -> None:
    """obj is what node's _target_ makes (a class, or a factory by its return type), and keeps these
    settings."""
    if "_target_" not in node:
        assert obj is None, f"{node} builds nothing, yet the Run holds {obj!r}"
        return
    target = get_object(node._target_)
    made = target if isinstance(target, type) else get_type_hints(target)["return"]
    assert isinstance(obj, made), f"expected a {made.__name__} from {node._target_}, the Run holds {obj!r}"
    for key in (k for k in settings if k in node):
        assert getattr(obj, key) == node[key], (f"{key}: the config says {node[key]!r}, "
                                                f"the object {getattr(obj, key)!r}")


def pipeline_stages(cfg, run) -> None:
    wanted = ordered_stages(cfg.pipeline)
    assert run.resources.pipeline.names == list(wanted)
    for stage, node in zip(run.resources.pipeline.stages, wanted.values()):
        built_from(node, stage)


def synthesizer(cfg, run) -> None:
    built_from(cfg.tts, run.resources.synthesizer)
    assert run.resources.pipeline.get("schedule").synthesizer is run.resources.synthesizer


def safety_hook(cfg, run) -> None:
    """The checker is wrapped into the sequencer's hook: it must reject an arm swung into the torso."""
    hook = run.resources.sequencer.safety
    if "_target_" not in cfg.safety:
        assert hook is None
        return
    inward = run.resources.library.neutral_entry.q[0].copy()
    inward[7], inward[8] = -0.5, 0.9
    assert hook(np.array([inward])) and hook(np.array([run.resources.library.neutral_entry.q[0]])) is None


def arm_law_applied_by_the_simulator(cfg, run) -> None:
    """Not built on its own: the backends read it by interpolation (MuJoCo applies it, G1 sends it)."""
    law = run.resources.backend.law
    assert (law.name, law.kp, law.gravity_compensation) == (cfg.arm_law.name, cfg.arm_law.kp,
                                                            cfg.arm_law.gravity_compensation)
    assert run.resources.backend.tracking_lag_s == cfg.arm_law.tracking_lag_s
    assert run.resources.pipeline.get("schedule").timeline.lag_s == cfg.arm_law.tracking_lag_s


def prompt_read_by_the_planner(cfg, run) -> None:
    """Not built on its own: the chat planners read it by interpolation (planner/llm.yaml)."""
    raw = OmegaConf.to_container(cfg.planner, resolve=False)
    assert raw["template"] == "${prompt.template}" and raw["demonstrations"] == "${prompt.demonstrations}"
    planner = run.resources.planner
    assert planner.template.path == Path(cfg.prompt.template).expanduser()
    assert (planner.demonstrations
            == load_demonstrations(cfg.prompt.demonstrations)[:cfg.prompt.max_demonstrations])


CONSUMERS = {
    "planner": lambda cfg, run: built_from(cfg.planner, run.resources.planner),
    "prompt": prompt_read_by_the_planner,
    "library": lambda cfg, run: built_from(cfg.library, run.resources.library, "neutral", "limit_margin"),
    "backend": lambda cfg, run: built_from(cfg.backend, run.resources.backend),
    "pipeline": pipeline_stages,
    "tts": synthesizer,
    "safety": safety_hook,
    "sequencer": lambda cfg, run: built_from(cfg.sequencer, run.resources.sequencer, "blend_s", "hold_s",
                                             "recover_s", "interrupt_blend_s", "neutral_tolerance",
                                             "preempt_after_s", "stall_stop_late_s"),
    "asr": lambda cfg, run: built_from(cfg.asr, run.resources.asr, "model", "api_base", "language"),
    "player": lambda cfg, run: built_from(cfg.player, run.resources.player, "sink", "latency_s"),
    "thinking": lambda cfg, run: built_from(cfg.thinking, run.runner.thinking, "motion", "repeats"),
    "arm_law": arm_law_applied_by_the_simulator,
    "posture": lambda cfg, run: built_from(cfg.posture, run.resources.sequencer.posture.settings,
                                           "idle_motion", "transition_s", "idle_amplitude", "breath_period_s",
                                           "fade_in_s"),
}


def cases() -> list:
    """Every option of every default group; an unbuildable one is listed (skipped) with its reason."""
    params = []
    for group in DEFAULTS:
        for option in sorted(path.stem for path in (CONFIG_DIR / group).glob("*.yaml")):
            reason = UNBUILDABLE.get((group, option))
            params.append(pytest.param(group, option, id=f"{group}={option}",
                                       marks=[pytest.mark.skip(reason=reason)] if reason else []))
    return params


@pytest.mark.parametrize("group, option", cases())
def test_the_group_is_built_into_the_run(group, option, tmp_path, monkeypatch):
    consumer = CONSUMERS.get(group)
    assert consumer is not None, (
        f"config group {group!r} is in conf/config.yaml's defaults but nothing says where the build puts it: "
        f"build cfg.{group} in emopose/build.py and add '{group}' to CONSUMERS in {Path(__file__).name}")
    # hosted planners check for a key; nothing is called
    monkeypatch.setenv("OPENAI_API_KEY", "sk-never-sent")
    chosen = {"planner": "keyword", group: option}  # keyword: nothing trains or downloads
    cfg = compose_config([f"{g}={o}" for g, o in chosen.items()] + CONSUMED_WITH.get(group, []))
    if "client" in cfg.planner:  # LLM planners probe their endpoint at build; there is no server here
        cfg.planner.client.probe = False
    with build_run(cfg, tmp_path) as run:
        consumer(cfg, run)


def test_a_laws_tracking_lag_reaches_the_backend_and_the_timeline(tmp_path):
    cfg = compose_config(["planner=keyword", "backend=mujoco", "arm_law=robot_gravity"])
    assert cfg.arm_law.tracking_lag_s > 0  # the default law's lag is 0, which would prove nothing
    with build_run(cfg, tmp_path) as run:
        arm_law_applied_by_the_simulator(cfg, run)


def test_every_consumer_names_a_group_in_the_defaults():
    assert set(CONSUMERS) <= set(DEFAULTS), f"stale entries: {sorted(set(CONSUMERS) - set(DEFAULTS))}"
