"""Every option of every config group composes and instantiates; bad overrides fail clearly."""

from __future__ import annotations

import inspect

import pytest
from hydra.errors import ConfigCompositionException
from hydra.utils import instantiate
from omegaconf import OmegaConf

from emopose.build import ConfigError, build_run, make, make_with
from emopose.config import CONFIG_DIR
from emopose.llm.client import LLMClient

HEAVY_PLANNERS = {"local", "sbert_centroids", "annotate"}  # load MiniLM (annotate: via local)
# tour is not in the primary defaults (tour experiments add it); tour files: tests/tour/test_scenario.py
GROUPS = sorted(p.name for p in CONFIG_DIR.iterdir() if p.is_dir() and p.name not in ("experiment", "tour"))
NESTED = {"llm": ("planner=llm", "planner.client")}  # composed inside an option of another group, at this key


def options(group: str) -> list[str]:
    return sorted(p.stem for p in (CONFIG_DIR / group).glob("*.yaml"))


@pytest.mark.parametrize("group,option", [(g, o) for g in GROUPS for o in options(g)])
def test_every_group_option_composes(group, option, library, compose):
    """Composition only; tests/test_config_consumed.py builds every option into a Run."""
    if group in NESTED:
        parent, key = NESTED[group]
        node = OmegaConf.select(compose(parent, f"{group}@{key}={option}"), key)
    else:
        node = compose(f"{group}={option}")[group]
    assert node is not None
    if group == "planner" and option not in HEAVY_PLANNERS:
        assert make_with(node, group, {"library": library}).name
    if group == "llm":
        assert isinstance(make(node, group), LLMClient)


def test_chat_planners_take_one_client_node_and_copy_none_of_its_settings(compose):
    """The client's settings live in conf/llm/ only: a planner option may override a few under `client:`."""
    settings = set(inspect.signature(LLMClient).parameters)
    for option in ("llm", "llm_local", "direct_label", "annotate"):
        text = (CONFIG_DIR / "planner" / f"{option}.yaml").read_text()
        planner = OmegaConf.create(text)
        assert not settings & set(planner), f"planner/{option}.yaml repeats {sorted(settings & set(planner))}"
        assert compose(f"planner={option}").planner.client._target_ == "emopose.llm.client.LLMClient"


@pytest.mark.parametrize("experiment", options("experiment"))
def test_every_experiment_composes_and_builds_its_job(experiment, tmp_path, compose):
    recording = tmp_path / "session.mcap"
    recording.write_bytes(b"\x89MCAP0\r\n")  # the MCAP magic: what a job checks before it loads anything
    required = {"replay": [f"mcap={recording}"], "recording_report": [f"recording={recording}"]}
    cfg = compose(f"+experiment={experiment}", *required.get(experiment, []))
    job = instantiate(cfg.job, _convert_="all")
    assert callable(job)


def test_default_config_builds_a_run(tmp_path, compose):
    with build_run(compose("planner=keyword"), tmp_path) as run:
        assert run.resources.pipeline.names == ["parse", "resolve", "modulate", "schedule", "sequence",
                                                "dispatch"]
        assert len(run.resources.library.names) == 31
        assert run.runner.pipeline is run.resources.pipeline and not run.session.is_open


def test_the_tour_pipeline_adds_aim_after_modulate_and_keeps_the_rest(tmp_path, compose):
    with build_run(compose("pipeline=tour", "planner=keyword"), tmp_path) as run:
        pipeline = run.resources.pipeline
        assert pipeline.names == ["parse", "resolve", "modulate", "aim", "schedule", "sequence", "dispatch"]
        assert pipeline.get("dispatch").until == "none" and pipeline.get("aim").scene is run.resources.scene


def test_a_stage_without_a_place_in_the_order_is_refused(tmp_path, compose):
    cfg = compose("planner=keyword", "+pipeline.stages.extra._target_=emopose.stages.parse.Parse")
    with pytest.raises(ConfigError, match="\\['extra'\\] have no place in the order"):
        build_run(cfg, tmp_path)


def test_unknown_group_option_is_a_clear_error(compose):
    with pytest.raises(ConfigCompositionException, match="planner"):
        compose("planner=gpt7")


def test_wrong_stage_value_names_the_key(tmp_path, compose):
    cfg = compose("pipeline.stages.schedule.mode=sideways", "planner=keyword")
    with pytest.raises(ConfigError, match="pipeline.stages.schedule"):
        build_run(cfg, tmp_path)


def test_hosted_llm_without_a_key_is_refused_before_the_run(tmp_path, monkeypatch, compose):
    monkeypatch.delenv("OPENAI_API_KEY", raising=False)
    cfg = compose("planner=llm", "planner.client.model=openai/gpt-4o-mini")
    with pytest.raises(ConfigError, match="OPENAI_API_KEY"):
        build_run(cfg, tmp_path)


def test_an_ablated_pipeline_is_a_one_line_config_error(tmp_path, compose):
    cfg = compose("planner=keyword", "pipeline.stages.modulate=null")
    with pytest.raises(ConfigError, match="pipeline: stage 'schedule' reads \\['modulated'\\]"):
        build_run(cfg, tmp_path)
