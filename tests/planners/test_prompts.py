"""Prompt files, the library guide, and the planner configs composed through Hydra."""

from __future__ import annotations

import re

import pytest

from emopose import CLASSES
from emopose.build import ConfigError, make_with
from emopose.config import PROJECT_ROOT
from emopose.planners.base import PlannerMode
from emopose.planners.chat.direct_label import DirectLabelPlanner
from emopose.planners.chat.guide import library_guide
from emopose.planners.chat.llm import LLMPlanner
from emopose.planners.chat.prompting import PromptError, PromptTemplate


def _section(path, title: str) -> str:
    text = PromptTemplate.load(path).text
    return re.search(rf"^## {title}\n(.*?)(?=^## )", text, re.DOTALL | re.MULTILINE).group(1)


def test_both_templates_share_the_class_definitions():
    structured = _section(PROJECT_ROOT / "prompts/structured.md", "Classes")
    assert structured == _section(PROJECT_ROOT / "prompts/direct_label.md", "Classes")
    listed = [line.split(":")[0][2:] for line in structured.splitlines() if line.startswith("- ")]
    assert listed == list(CLASSES)


def test_template_header_is_stripped_and_fields_declared():
    template = PromptTemplate.load(PROJECT_ROOT / "prompts/structured.md")
    assert not template.text.startswith("<!--")
    assert template.fields == {"library_guide", "demonstrations", "max_gestures", "mode"}
    with pytest.raises(PromptError, match="labels"):
        template.require("labels")


def test_guide_lists_classes_in_order_with_defaults(writable_library):
    guide = library_guide(writable_library)
    heads = [line[:-1] for line in guide.splitlines() if not line.startswith(" ")]
    assert heads == list(CLASSES)
    assert "  - pointing_a (class default): pointing a test motion" in guide
    assert "neutral_rest" not in guide  # the built-in rest pose is not offered as a gesture
    assert library_guide(writable_library) is guide  # cached while the version is unchanged
    writable_library.reload()
    assert library_guide(writable_library) == guide and library_guide(writable_library) is not guide


def test_planner_configs_compose_and_build(writable_library, demonstrations_file, tmp_path, compose):
    common = [f"prompt.demonstrations={demonstrations_file}", f"planner.client.cache_dir={tmp_path}"]
    resources = {"library": writable_library}
    llm = make_with(compose("planner=llm", *common).planner, "planner", resources)
    assert isinstance(llm, LLMPlanner) and llm.client.temperature == 0.7 and llm.mode is PlannerMode.NARRATE
    assert llm.library is writable_library
    label = make_with(compose("planner=direct_label", *common).planner, "planner", resources)
    assert isinstance(label, DirectLabelPlanner) and label.template.path.name == "direct_label.md"
    assert label.client.model == llm.client.model and label.client.max_tokens == llm.client.max_tokens
    wrong = ["planner=llm", f"planner.template={PROJECT_ROOT / 'prompts/direct_label.md'}", *common]
    with pytest.raises((ConfigError, PromptError), match="library_guide"):
        make_with(compose(*wrong).planner, "planner", resources)


def test_demonstration_lines_follow_the_mode(demonstrations_file):
    from emopose.planners.chat.prompting import load_demonstrations, plan_demonstrations

    demos = load_demonstrations(demonstrations_file)
    demos = [d.__class__(d.id, d.text, "Robot line " + d.id, d.gestures) for d in demos]
    assert "User: Robot line demo-1" in plan_demonstrations(demos, "narrate")
    assert f"User: {demos[0].text}" in plan_demonstrations(demos, "respond")


def test_prompt_text_does_not_leak_suite_items():
    """Everything the model is shown besides the suite item itself: quoted rule examples and demonstration
    replies (narrate mode shows the replies). Same near-duplicate rule as tests/test_leakage.py."""
    import json

    from emopose.bench.near_duplicates import Text, cross_duplicates

    suites = []
    for path in sorted((PROJECT_ROOT / "experiments").glob("*/*suite*.jsonl")) + sorted(
            (PROJECT_ROOT / "experiments").glob("bench/*.jsonl")):
        for row in map(json.loads, filter(str.strip, path.read_text(encoding="utf-8").splitlines())):
            suites.append(Text.of(f"{path.stem}:{row['id']}", row["text"]))
    assert len(suites) >= 480 + 320 + 320, "experiments/ is missing suite files: they ship with the repo"
    shown = []
    for name in ("structured.md", "direct_label.md"):
        quotes = re.findall(r'"([^"$]{6,})"', (PROJECT_ROOT / "prompts" / name).read_text())
        for k, quote in enumerate(quotes):
            shown.append(Text.of(f"{name}:{k}", quote))
    demos = (PROJECT_ROOT / "prompts/demonstrations.jsonl").read_text(encoding="utf-8")
    for row in map(json.loads, filter(str.strip, demos.splitlines())):
        shown.append(Text.of(f"demo-reply:{row['id']}", row["reply"]))
    pairs = cross_duplicates(suites, shown)
    assert not pairs, pairs[:5]
