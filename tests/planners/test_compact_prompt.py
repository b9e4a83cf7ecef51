"""Prompts that fit small models: prompt=compact, the short guide, and the planner=llm_local preset."""

from __future__ import annotations

import pytest

from emopose import CLASSES
from emopose.build import ConfigError, make, make_with
from emopose.llm.check import prompt_tokens
from emopose.planners.base import PlanRequest
from emopose.planners.chat.guide import library_guide
from emopose.planners.chat.planner import PROBE_LINE

COMPACT_TOKEN_BUDGET = 1200  # issue 17: small local models get a prompt of about 1,000 tokens or less


def _planner(compose, *overrides):
    cfg = compose(*overrides)
    return make_with(cfg.planner, "planner", {"library": make(cfg.library, "library")})


def test_the_compact_prompt_fits_the_budget_with_the_g1_library(compose, tmp_path):
    full = _planner(compose, "planner=llm", f"planner.client.cache_dir={tmp_path}")
    compact = _planner(compose, "planner=llm", "prompt=compact", f"planner.client.cache_dir={tmp_path}")
    request = PlanRequest(PROBE_LINE)
    tokens = prompt_tokens(compact.client.model, compact.messages(request))
    assert tokens <= COMPACT_TOKEN_BUDGET < prompt_tokens(full.client.model, full.messages(request))
    system = compact.system_prompt()
    assert "Example 2" in system and "Example 3" not in system  # prompt.max_demonstrations: 2
    assert "open_arms" in system and "Mode: narrate" in system and "${" not in system


def test_the_short_guide_is_one_line_of_names_per_class(writable_library):
    guide = library_guide(writable_library, "short").splitlines()
    assert [line.split(":")[0] for line in guide] == list(CLASSES)
    assert guide[0] == "pointing: pointing_a, pointing_b"  # the class default first
    assert "neutral_rest" not in "\n".join(guide)


def test_llm_local_is_a_preset_for_a_one_slot_local_server(compose, tmp_path):
    local = _planner(compose, "planner=llm_local", f"planner.client.cache_dir={tmp_path}")
    client = local.client  # conf/llm/local_server.yaml
    assert client.concurrency == 1 and client.timeout_s >= 120
    assert client.temperature == 0 and not local.sampled
    assert client.api_base.startswith("http://127.0.0.1:") and local.structured_output == "json_schema"
    assert local.template.path.name == "compact.md" and client.context_window
    assert prompt_tokens(client.model, local.messages(PlanRequest(PROBE_LINE))) + client.max_tokens \
        <= client.context_window


def test_the_local_server_client_can_serve_planner_llm(compose, tmp_path):
    """The client is its own group: planner=llm keeps its prompt and takes the local server's client."""
    planner = _planner(compose, "planner=llm", "llm@planner.client=local_server",
                       f"planner.client.cache_dir={tmp_path}")
    assert planner.client.api_base.startswith("http://127.0.0.1:") and planner.client.concurrency == 1
    assert planner.template.path.name == "structured.md"


@pytest.mark.parametrize("setting", ["max_demonstrations=0", "client.context_window=0",
                                     "client.abort_after=0", "client.concurrency=0"])
def test_settings_below_one_are_refused(compose, tmp_path, setting):
    with pytest.raises(ConfigError, match=f"planner.{setting.split('=')[0]} = 0 must be >= 1"):
        _planner(compose, "planner=llm", f"planner.client.cache_dir={tmp_path}", f"planner.{setting}")
