"""Cancel while a reply is planned (issue 31 item 7): the page's Cancel abandons the pending planner call,
the thinking gesture stops, the line is counted as cancelled (turns.jsonl, results) and stays out of the
dialogue; while the model call is retried the live state says how often. A held stub planner stands in
for a slow model: it answers when the test lets it (events, no clock)."""

from __future__ import annotations

import json
import threading
from types import SimpleNamespace

import pytest
from fastapi.testclient import TestClient

from emopose.llm.counters import CallCounters
from emopose.planners.base import PlannerOutput
from emopose.turn.planning_call import AbandonableCall, PlanningCancelled
from emopose.turn.thinking import THINKING_LABEL
from tests.web.conftest import LOCAL
from tests.web.test_api import WS

GUARD_S = 60  # only a hung test waits this long; nothing is timed


class HeldPlanner:
    """Plans once the test releases it; counts retries on a client, as the LLM planners do."""

    name, sampled = "held", False

    def __init__(self) -> None:
        self.entered, self.release = threading.Event(), threading.Event()
        self.client = SimpleNamespace(counters=CallCounters())
        self.answers = 0

    def plan(self, request) -> PlannerOutput:
        self.entered.set()
        self.release.wait(GUARD_S)
        self.answers += 1
        return PlannerOutput(raw=json.dumps({"reply": request.utterance, "gestures": []}))


def thinking_commands(sequencer) -> list:
    return [c for c in [sequencer.active, *sequencer.pending] if c is not None and c.label == THINKING_LABEL]


def test_cancel_abandons_the_call_stops_thinking_and_counts_the_line(serve_app):
    app, session = serve_app("thinking=chin_stroke")
    planner = session.run.runner.planner = HeldPlanner()
    sequencer = session.res.sequencer
    with TestClient(app, base_url=LOCAL) as client:
        said: dict = {}
        asking = threading.Thread(target=lambda: said.update(
            client.post("/api/say", json={"text": "Where are the toilets?"}).json()))
        asking.start()
        assert planner.entered.wait(GUARD_S)
        planning = client.get("/api/status").json()["planning"]
        assert planning["retries"] == 0 and thinking_commands(sequencer)  # the robot thinks meanwhile
        planner.client.counters.add(retries=2)  # the model call failed twice and is being retried
        assert client.get("/api/status").json()["planning"]["retries"] == 2
        assert client.post("/api/cancel", json={"turn": planning["turn"] + 1}).json()["cancelled"] is False
        answer = client.post("/api/cancel", json={"turn": planning["turn"]}).json()
        assert answer == {"cancelled": True, "turn": planning["turn"]}
        asking.join(GUARD_S)
        assert said["type"] == "turn_cancelled" and said["utterance"] == "Where are the toilets?"
        assert planner.answers == 0  # abandoned, not answered: the stub still holds its call
        assert thinking_commands(sequencer) == []
        assert client.get("/api/status").json()["planning"] is None
        assert client.post("/api/cancel", json={}).json()["cancelled"] is False  # nothing is planned now
        planner.release.set()  # the abandoned call answers late; its plan is dropped
        turn = client.post("/api/say", json={"text": "Thank you."}).json()
    assert turn["type"] == "turn" and turn["reply"] == "Thank you."
    assert [m["type"] for m in session.log_since(0) if m["type"].startswith("turn")] == [
        "turn_started", "turn_cancelled", "turn_started", "turn"]
    assert all("toilets" not in m["content"] for m in session.run.runner.dialogue.messages)
    rows = (session.run.session.run_dir / "turns.jsonl").read_text().splitlines()
    assert [json.loads(r)["plan source"] for r in rows][0] == "cancelled while planning"
    results = session.tally.results()
    assert results["cancelled"] == 1 and results["turns"] == 1
    assert "cancelled while planning" in session.tally.markdown()


def test_a_cancel_on_the_websocket_names_its_line(client):
    with client.websocket_connect(WS) as page:
        assert page.receive_json()["type"] == "hello"
        page.send_json({"type": "cancel", "turn": 12345})  # a line that is not being planned
        for _ in range(200):
            message = page.receive_json()
            if message["type"] == "cancel_refused":
                break
        assert "nothing is being planned" in message["message"]
        page.send_json({"type": "cancel", "turn": "12"})  # strict: not coerced
        for _ in range(200):
            message = page.receive_json()
            if message["type"] == "error":
                break
        assert "turn" in message["message"]


def test_a_cancel_before_the_planner_call_starts_cancels_the_turn(serve_app):
    """The Cancel lands in the window between turn_started and the planner call (deterministically: sent
    from inside the turn's own work before the call); the turn is cancelled and the call never starts."""
    app, session = serve_app()
    runner = session.run.runner
    planner = runner.planner = HeldPlanner()
    planner.release.set()  # were it called, it would answer at once
    answers: list[dict] = []
    with TestClient(app, base_url=LOCAL) as client:
        request = runner.dialogue.request

        def cancel_then_request(*args, **kwargs):  # runs after turn_started, before the planner call
            started = [m for m in session.log_since(0) if m["type"] == "turn_started"][-1]
            answers.append(client.post("/api/cancel", json={"turn": started["id"]}).json())
            return request(*args, **kwargs)

        runner.dialogue.request = cancel_then_request
        said = client.post("/api/say", json={"text": "Where are the toilets?"}).json()
        runner.dialogue.request = request
        turn = client.post("/api/say", json={"text": "Thank you."}).json()  # the next line is not cancelled
    assert answers[0]["cancelled"] is True and said["type"] == "turn_cancelled"
    assert turn["type"] == "turn" and turn["reply"] == "Thank you."
    assert planner.answers == 1 and all("toilets" not in m["content"] for m in runner.dialogue.messages)


def test_a_cancel_after_the_turn_ended_arms_nothing():
    """expect() opens the window, settle() closes it: a late Cancel is refused and the next call runs."""
    call = AbandonableCall()
    call.expect()
    assert call.abandon() is True and call.abandon() is False
    with pytest.raises(PlanningCancelled):
        call.claim()  # a streamed reply's start: the stream is never opened
    call.expect()
    assert call.run(lambda: "plan") == "plan" and call.abandon() is False  # the plan has arrived
    call.expect()
    call.settle()  # the line ended without a call (an error before it)
    assert call.abandon() is False and call.run(lambda: "next") == "next"
