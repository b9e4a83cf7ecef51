"""Fixtures for the LLM planner tests: a live fake OpenAI server and planners pointed at it."""

from __future__ import annotations

import functools
import inspect
import json
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))  # fake_openai is a helper module, not a test module
from fake_openai import FakeOpenAI

from emopose.config import PROJECT_ROOT

# Made-up demonstrations (the real ones live in prompts/demonstrations.jsonl); five, like the paper.
DEMOS = [
    ("demo-1", "Hello and welcome, the coffee machine is just behind you.",
     [("welcoming", "Hello and welcome"), ("pointing", "just behind you")]),
    ("demo-2", "I'm so sorry about your grandmother; take all the time you need.",
     [("comforting", "I'm so sorry")]),
    ("demo-3", "Absolutely, that plan works for me.", [("agreeing", "Absolutely")]),
    ("demo-4", "Hmm, I doubt the bus runs this late.", [("doubting", "I doubt")]),
    ("demo-5", "The backup must finish before midnight, no exceptions.", [("emphasizing", "must finish")]),
]


@pytest.fixture
def demonstrations_file(tmp_path: Path) -> Path:
    path = tmp_path / "demonstrations.jsonl"
    lines = []
    for demo_id, text, acts in DEMOS:
        gestures = [{"class": cls, "variant": None, "intensity": 3, "trigger": trigger, "confidence": 0.9}
                    for cls, trigger in acts]
        lines.append(json.dumps({"id": demo_id, "text": text, "reply": text, "gestures": gestures}))
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.fixture
def fake_openai() -> Iterator[FakeOpenAI]:
    with FakeOpenAI() as server:
        yield server


@pytest.fixture
def planner_kwargs(fake_openai: FakeOpenAI, demonstrations_file: Path, tmp_path: Path) -> dict:
    """Settings for a planner talking to the fake server, with a private cache and near-zero backoff (the
    client's and the planner's together: make_chat sorts them)."""
    return {"model": "openai/fake-model", "api_base": fake_openai.url, "temperature": 0.7,
            "timeout_s": 5.0, "max_retries": 3, "backoff_s": 0.001, "backoff_max_s": 0.01,
            "cache": True, "cache_dir": str(tmp_path / "llm-cache"),
            "demonstrations": str(demonstrations_file)}


@pytest.fixture
def make_chat(writable_library, planner_kwargs) -> Callable:
    """make_chat(Class, template, **settings): a chat planner whose LLMClient takes the settings it names
    (planner.client.* in the config) and whose constructor takes the rest, plus the library if it asks."""
    from emopose.llm.client import LLMClient

    client_keys = set(inspect.signature(LLMClient).parameters)

    def make(cls, template: str, **overrides):
        settings = {**planner_kwargs, "template": str(PROJECT_ROOT / template), **overrides}
        client = LLMClient(**{k: v for k, v in settings.items() if k in client_keys})
        own = {k: v for k, v in settings.items() if k not in client_keys}
        if "library" in inspect.signature(cls).parameters:
            own["library"] = writable_library
        return cls(client=client, **own)

    return make


@pytest.fixture
def make_llm_planner(make_chat) -> Callable:
    from emopose.planners.chat.llm import LLMPlanner

    return functools.partial(make_chat, LLMPlanner, "prompts/structured.md")


@pytest.fixture
def make_label_planner(make_chat) -> Callable:
    from emopose.planners.chat.direct_label import DirectLabelPlanner

    return functools.partial(make_chat, DirectLabelPlanner, "prompts/direct_label.md")
