"""Every option of every config group composes and instantiates; bad overrides fail clearly."""

from __future__ import annotations

import pytest
from hydra import compose, initialize_config_dir
from hydra.errors import ConfigCompositionException
from hydra.utils import instantiate

from emopose.build import ConfigError, build_context, make
from emopose.config import CONFIG_DIR

HEAVY_PLANNERS = {"local", "sbert_centroids"}  # load MiniLM: covered by the slow planner tests
# tour is not in the primary defaults (tour experiments add it); tour files: tests/tour/test_scenario.py
GROUPS = sorted(p.name for p in CONFIG_DIR.iterdir() if p.is_dir() and p.name not in ("experiment", "tour"))


def options(group: str) -> list[str]:
    return sorted(p.stem for p in (CONFIG_DIR / group).glob("*.yaml"))


def compose_with(*overrides: str):
    with initialize_config_dir(config_dir=str(CONFIG_DIR), version_base="1.3"):
        return compose("config", overrides=list(overrides))


@pytest.mark.parametrize("group,option", [(g, o) for g in GROUPS for o in options(g)])
def test_every_group_option_composes_and_instantiates(group, option, library):
    cfg = compose_with(f"{group}={option}")
    node = cfg[group]
    if group == "planner" and option in HEAVY_PLANNERS:
        pytest.skip("loads a sentence encoder; instantiated in tests/planners (slow)")
    if group == "planner":
        assert make(node, group, library=library).name
    elif group == "pipeline":
        for name, stage in node.stages.items():
            assert make(stage, name).name == name
    elif group == "sequencer":
        from emopose.trajectory import TrajectoryBuilder

        make(node, group, builder=TrajectoryBuilder(library.limits), neutral=library.neutral_entry.q[0])
    elif group in ("library", "prompt"):
        assert node is not None
    else:
        make(node, group)


@pytest.mark.parametrize("experiment", options("experiment"))
def test_every_experiment_composes_and_builds_its_job(experiment, tmp_path):
    recording = tmp_path / "session.mcap"
    recording.touch()
    required = {"replay": [f"mcap={recording}"]}  # experiments with a mandatory argument
    cfg = compose_with(f"+experiment={experiment}", *required.get(experiment, []))
    job = instantiate(cfg.job, _convert_="all")
    assert callable(job)


def test_default_config_builds_a_context(tmp_path):
    ctx = build_context(compose_with("planner=keyword"), tmp_path)
    assert ctx.pipeline.names == ["parse", "resolve", "modulate", "schedule", "sequence", "dispatch"]
    assert len(ctx.library.names) == 31


def test_unknown_group_option_is_a_clear_error():
    with pytest.raises(ConfigCompositionException, match="planner"):
        compose_with("planner=gpt7")


def test_wrong_stage_value_names_the_key(tmp_path):
    cfg = compose_with("pipeline.stages.schedule.mode=sideways", "planner=keyword")
    with pytest.raises(ConfigError, match="pipeline.stages.schedule"):
        build_context(cfg, tmp_path)


def test_hosted_llm_without_a_key_is_refused_before_the_run(tmp_path, monkeypatch):
    monkeypatch.delenv("OPENAI_API_KEY", raising=False)
    cfg = compose_with("planner=llm", "planner.model=openai/gpt-4o-mini")
    with pytest.raises(ConfigError, match="OPENAI_API_KEY"):
        build_context(cfg, tmp_path)
