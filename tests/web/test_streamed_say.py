"""The web UI with a streaming planner: each sentence is published as a turn as soon as it is handed over,
and an interrupt cancels the stream (the local streaming server sees the connection closed)."""

from __future__ import annotations

import sys
import threading
import time

import pytest

from emopose.config import PROJECT_ROOT
from emopose.llm.client import LLMClient
from emopose.planners.baselines.keyword import KeywordPlanner
from emopose.planners.chat.annotate import AnnotatePlanner

sys.path.insert(0, str(PROJECT_ROOT / "tests" / "planners"))  # the fake servers are helpers, not tests
from fake_openai import FakeOpenAI  # noqa: E402
from fake_stream import streamed, tokens  # noqa: E402

REPLY = "Welcome to the lab! The charging dock is over there. Please do not touch the arm."
FIRST = len(tokens("Welcome to the lab!")) + 1


@pytest.fixture
def server():
    with FakeOpenAI() as running:
        yield running


@pytest.fixture
def live(serve_app, server, tmp_path):
    _, session = serve_app()
    runner = session.run.runner
    runner.planner = AnnotatePlanner(
        library=session.res.library, template=str(PROJECT_ROOT / "prompts/annotate.md"),
        demonstrations=str(PROJECT_ROOT / "prompts/demonstrations.jsonl"), annotator=KeywordPlanner(),
        stream=True, client=LLMClient(model="openai/fake-model", api_base=server.url, cache=False,
                                      max_retries=0, timeout_s=10))
    return session


def _turns(session) -> list[dict]:
    return [m for m in session.log_since(0) if m["type"] == "turn"]


def test_each_sentence_is_published_as_its_turn_and_speech_is_chained(live, server):
    server.default = streamed(REPLY)
    last = live._say("Where can I charge my phone?", None)
    turns = _turns(live)
    assert [t["reply"] for t in turns] == ["Welcome to the lab!", "The charging dock is over there.",
                                          "Please do not touch the arm."]
    assert last["turn_id"] == turns[-1]["turn_id"]
    starts = [t["speech_start"] for t in turns]
    assert starts == sorted(starts) and len(set(starts)) == 3
    assert live.run.runner.dialogue.messages[-1]["content"] == REPLY


def test_an_interrupt_cancels_the_streaming_reply(live, server):
    hold = threading.Event()
    server.default = streamed(REPLY, tokens_per_s=50, hold=hold, hold_after=FIRST)
    said = {}
    worker = threading.Thread(target=lambda: said.update(live._say("Where can I charge my phone?", None)))
    worker.start()
    for _ in range(1000):  # the first sentence is published while the model is held
        if _turns(live):
            break
        time.sleep(0.01)
    interrupted = live.interrupt()
    hold.set()
    worker.join(30)
    assert ([t["reply"] for t in _turns(live)] == ["Welcome to the lab!"]
            and interrupted["type"] == "interrupted")
    assert said["type"] == "reply_stopped" and said["cancelled"] and said["sentences"] == 1
    assert live.res.sequencer.pending == []
    for _ in range(500):
        if server.streams_dropped or server.answered:
            break
        time.sleep(0.01)
    assert server.streams_dropped == 1
