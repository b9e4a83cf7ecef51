"""Every stage setting in conf/pipeline/ equals the stage's code default, so the two cannot drift apart.

The YAML is what runs (python -m emopose); the code defaults are what a stage built by hand gets (the
unit tests, Pose Studio's and the library check's fallbacks). A pipeline file's deliberate change of
another's setting (tour.yaml's dispatch.until) is an override, not a default: each stage is checked in
the file that adds it.
"""

from __future__ import annotations

import dataclasses
import inspect
from typing import Any

import pytest
from hydra.utils import get_class
from omegaconf import DictConfig, OmegaConf

from tests.conftest import compose_config

PIPELINES = ("default", "tour")


def stages_added(pipeline: str) -> dict[str, DictConfig]:
    """The stage nodes a pipeline file adds to the ones it builds on (default.yaml: all six)."""
    stages = compose_config([f"pipeline={pipeline}"]).pipeline.stages
    base = set() if pipeline == "default" else set(compose_config().pipeline.stages)
    return {name: node for name, node in stages.items() if name not in base}


def code_defaults(target: str) -> dict[str, Any]:
    """The constructor's default of every parameter that has one."""
    cls = get_class(target)
    if not dataclasses.is_dataclass(cls):
        parameters = inspect.signature(cls).parameters.items()
        return {name: p.default for name, p in parameters if p.default is not p.empty}
    fields = dataclasses.fields(cls)
    defaults = {f.name: f.default for f in fields if f.default is not dataclasses.MISSING}
    defaults |= {f.name: f.default_factory() for f in fields if f.default_factory is not dataclasses.MISSING}
    return defaults


def disagreements(node: DictConfig, where: str) -> list[str]:
    """'<where>.<key>: yaml X, code Y' for every setting of the node that differs from its code default."""
    defaults, found = code_defaults(node._target_), []
    for key, value in OmegaConf.to_container(node, resolve=True).items():
        if key == "_target_":
            continue
        if key not in defaults:
            found.append(f"{where}.{key}: in the YAML but the code has no default")
        elif isinstance(value, dict) and "_target_" in value:
            found += disagreements(node[key], f"{where}.{key}")
        elif _plain(value) != _plain(defaults[key]):
            found.append(f"{where}.{key}: yaml {value!r}, code {defaults[key]!r}")
    return found


def _plain(value: Any) -> Any:
    """Lists and tuples compare alike (YAML has no tuples); a settings object as its fields."""
    if dataclasses.is_dataclass(value):
        return _plain(dataclasses.asdict(value))
    if isinstance(value, list | tuple):
        return tuple(_plain(v) for v in value)
    return value


@pytest.mark.parametrize("pipeline", PIPELINES)
def test_every_yaml_stage_setting_equals_its_code_default(pipeline):
    stages = stages_added(pipeline)
    assert stages, f"pipeline={pipeline} adds no stage"
    found = [problem for name, node in stages.items() for problem in disagreements(node, name)]
    assert not found, "\n".join(found)


def test_a_disagreement_is_reported():
    node = OmegaConf.create({"_target_": "emopose.stages.modulate.Modulate", "margin": 0.05})
    assert disagreements(node, "modulate") == ["modulate.margin: yaml 0.05, code 0.02"]
