"""serve's posture layer: the page's typing puts the robot in its listening posture, a planned turn in its
thinking posture (the runner), rest otherwise; serve breathes between gestures unless told not to."""

from __future__ import annotations

import time

from fastapi.testclient import TestClient

from emopose.contract import EventKind
from emopose.execution.posture import LISTENING, REST, THINKING
from emopose.planners.baselines.keyword import KeywordPlanner
from tests.web.conftest import LOCAL

WS = "ws://127.0.0.1/ws"


def heading_for(sequencer, posture: str) -> bool:
    """Poll (the loop runs on its thread) until the stream heads for `posture`; False after 5 s."""
    end = time.monotonic() + 5.0
    while time.monotonic() < end:
        if sequencer.posture.heading == posture:
            return True
        time.sleep(0.02)
    return False


def handled(ws) -> None:
    """The page's messages are handled in order: a pong means every earlier one was."""
    ws.send_json({"type": "ping"})
    while ws.receive_json()["type"] != "pong":
        pass


def test_typing_takes_the_listening_posture_and_an_emptied_line_gives_it_up(serve_app):
    app, session = serve_app()
    sequencer = session.res.sequencer
    assert sequencer.posture.settings.idle_motion  # a live robot breathes (conf/experiment/serve.yaml)
    with TestClient(app, base_url=LOCAL) as client, client.websocket_connect(WS) as ws:
        ws.receive_json()
        ws.send_json({"type": "listening"})
        handled(ws)
        assert sequencer.posture.current == LISTENING and heading_for(sequencer, LISTENING)
        ws.send_json({"type": "listening", "active": False})
        handled(ws)
        assert heading_for(sequencer, REST)
        ws.send_json({"type": "listening", "active": "yes"})
        replies = (ws.receive_json() for _ in range(500))  # state pushes come in between
        error = next(m for m in replies if m["type"] in ("error", "pong"))
        assert error["type"] == "error" and "active" in error["message"]  # a boolean, not coerced
    recorded = [e.detail for e in sequencer.events if e.kind == EventKind.POSTURE]
    assert recorded == [LISTENING, REST]


def test_a_turn_is_planned_in_the_thinking_posture_and_spoken_from_rest(serve_app):
    app, session = serve_app()
    sequencer, seen = session.res.sequencer, []

    class Watching(KeywordPlanner):
        def plan(self, request):
            seen.append(sequencer.posture.current)
            return super().plan(request)

    session.run.runner.planner = Watching()
    session.run.runner.run("Hello there.")
    assert seen == [THINKING] and sequencer.posture.current == REST


def test_idle_motion_off_on_request(serve_app):
    _, session = serve_app("posture.idle_motion=false")
    assert not session.res.sequencer.posture.settings.idle_motion
