"""The web API on a live served context (dry_run, keyword planner, real-time control loop).

Covers the request edge (bad, oversized and malformed requests, path-traversal names), the access
token for network binds, the Pose Studio round trip (check, save, backup, overwrite) and the live
library: a motion saved through the API resolves and runs on the very next request.
"""

from __future__ import annotations

import time

import pytest
from fastapi.testclient import TestClient

from emopose import CONTROL_DT
from tests.web.conftest import LOCAL

WS = "ws://127.0.0.1/ws"


def wait_for(predicate, timeout_s: float = 5.0) -> bool:
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        if predicate():
            return True
        time.sleep(0.02)
    return False


def motion_body(client: TestClient, name: str, base: str = "face_wave", **extra) -> dict:
    """A valid new motion: an authored one with its interior wrist yaw nudged."""
    entry = client.get(f"/api/library/{base}").json()
    keyframes = [list(k) for k in entry["keyframes"]]
    for k in keyframes[1:-1]:
        k[13] += 0.1
    return {"name": name, "class": entry["class"], "description": "a test variant of the face wave",
            "keyframes": keyframes, **extra}


# -- the live robot --------------------------------------------------------------------------------
def test_info_and_a_typed_turn_with_timed_cues(client):
    info = client.get("/api/info").json()
    assert info["backend"] == "dry_run" and info["planner"] == "keyword" and info["asr"] is False
    turn = client.post("/api/say", json={"text": "Welcome! The robot arm is over there."}).json()
    assert turn["reply"] == "Welcome! The robot arm is over there."
    cues = turn["cues"]
    assert [c["class"] for c in cues] == ["welcoming", "pointing"]
    first = cues[0]
    assert turn["reply"][first["char_start"]:first["char_end"]].lower() == first["trigger"].lower()
    # the timeline plans each stroke to land just before its trigger word (the speech may wait for it)
    assert cues[0]["release_s"] < cues[0]["stroke_s"] < cues[1]["stroke_s"] <= turn["speech"]["duration_s"]
    assert wait_for(lambda: client.get("/api/status").json()["state"] != "idle")


def test_status_gives_the_loops_missed_deadlines_stalls_and_lateness(client):
    stats = client.app.state.session.run.session.loop.stats
    assert wait_for(lambda: client.get("/api/status").json()["loop"]["ticks"] > 0)
    stats.missed_deadlines += 7  # as a stall would count them
    stats.stalls += 2
    loop = client.get("/api/status").json()["loop"]
    assert loop["running"] and loop["missed"] == loop["missed_deadlines"] >= 7 and loop["stalls"] >= 2
    assert loop["missed_per_tick"] == pytest.approx(loop["missed_deadlines"] / loop["ticks"], rel=0.2)
    assert loop["lateness_ms_max"] >= loop["lateness_ms_p99"] >= 0 and loop["scheduling"] == "normal"


def test_each_cue_learns_where_its_stroke_actually_landed(client):
    turn = client.post("/api/say", json={"text": "Welcome! The robot arm is over there."}).json()

    def landed() -> list[dict]:
        log = client.get("/api/turns").json()["log"]
        return [m for m in log if m["type"] == "cue_stroke" and m["turn_id"] == turn["turn_id"]]

    assert wait_for(lambda: len(landed()) == 2, timeout_s=15)
    # The stroke is stamped at the first 20 ms tick within tolerance of its pose (up to a tick after the
    # planned crossing), and a timed gesture starts at the first tick after its release, which moves the
    # crossing by less than another tick; plus whatever the real-time loop reports it was late by on
    # this (possibly busy) machine.
    late_s = client.get("/api/status").json()["loop"]["lateness_ms_max"] / 1e3
    for update in landed():
        planned = turn["cues"][update["k"]]["stroke_s"]
        assert -CONTROL_DT <= update["executed_s"] - planned <= 2 * CONTROL_DT + late_s
    stored = next(m for m in client.get("/api/turns").json()["log"] if m.get("turn_id") == turn["turn_id"]
                  and m["type"] == "turn")
    assert all(c["stroke_executed_s"] is not None for c in stored["cues"])


def test_interrupt_clears_the_queue_and_blends(client):
    client.post("/api/say", json={"text": "Welcome! Look over there. This is really important. No, stop."})
    assert client.get("/api/status").json()["pending"]
    client.post("/api/interrupt", json={})
    status = client.get("/api/status").json()
    assert status["pending"] == [] and status["state"] == "blending"


def test_websocket_actions_and_malformed_messages(client):
    with client.websocket_connect(WS) as ws:
        hello = ws.receive_json()
        assert hello["type"] == "hello" and hello["backend"] == "dry_run"
        ws.send_text("{not json")
        ws.send_json({"type": "gesture", "name": "../../etc/passwd"})
        ws.send_bytes(b"\x00binary")
        ws.send_json({"type": "gesture", "name": "face_wave", "intensity": 4})
        errors, turn, seen = [], None, 0
        while (turn is None or len(errors) < 3) and seen < 200:
            message = ws.receive_json()
            seen += 1
            if message["type"] == "error":
                errors.append(message["message"])
            elif message["type"] == "turn":
                turn = message
        assert len(errors) == 3 and "invalid message" in errors[0] and "name" in errors[1]
        assert turn["cues"][0]["resolved"] == "face_wave" and turn["cues"][0]["rule"] == "exact"
        assert turn["cues"][0]["intensity"] == 4


# -- the request edge ------------------------------------------------------------------------------
@pytest.mark.parametrize("path, body, status", [
    ("/api/say", {}, 422),                                   # missing field
    ("/api/say", {"text": ""}, 422),                         # empty utterance
    ("/api/say", {"text": "hi", "extra": 1}, 422),           # unknown field
    ("/api/gesture", {"name": "face_wave", "intensity": 9}, 422),
    ("/api/gesture", {"name": "no_such_motion"}, 404),
    ("/api/studio/check", {"keyframes": [[0.0] * 13] * 3}, 422),  # 13 joints
    ("/api/studio/check", {"keyframes": [[0.0] * 14] * 2}, 422),  # a sequence needs >= 3 keyframes
    ("/api/resolve", {"class": "dancing"}, 422),
])
def test_bad_requests_get_a_4xx_with_a_json_message(client, path, body, status):
    response = client.post(path, json=body)
    assert response.status_code == status
    assert response.json()["error"]


def test_malformed_json_wrong_type_unknown_route_and_method(client):
    bad_json = client.post("/api/say", content=b"{oops", headers={"Content-Type": "application/json"})
    assert bad_json.status_code == 422 and "error" in bad_json.json()
    not_json = client.post("/api/say", content=b"text=hi", headers={"Content-Type": "text/plain"})
    assert not_json.status_code == 415 and "application/json" in not_json.json()["error"]
    assert client.get("/api/nothing").status_code == 404 and client.get("/api/nothing").json()["error"]
    assert client.get("/api/say").status_code == 405 and "error" in client.get("/api/say").json()
    nan = client.post("/api/studio/check", content=b'{"keyframes": [[NaN' + b", 0" * 13 + b"]]}",
                      headers={"Content-Type": "application/json"})
    assert nan.status_code == 422


def test_oversized_bodies_are_refused(client):
    big = b'{"text": "' + b"a" * 300_000 + b'"}'
    declared = client.post("/api/say", content=big, headers={"Content-Type": "application/json"})
    assert declared.status_code == 413 and "larger than" in declared.json()["error"]

    def chunks():  # no Content-Length: the limit must hold on the stream itself
        for _ in range(40):
            yield b"a" * 10_000

    streamed = client.post("/api/say", content=chunks(), headers={"Content-Type": "application/json"})
    assert streamed.status_code == 413


def test_unexpected_errors_are_json_without_a_traceback(serve_app, monkeypatch):
    app, session = serve_app()

    def broken(*args, **kwargs):
        raise RuntimeError("secret internals")

    monkeypatch.setattr(session.studio, "report", broken)
    with TestClient(app, base_url=LOCAL, raise_server_exceptions=False) as client:
        response = client.post("/api/studio/check", json={"keyframes": [[0.0] * 14] * 3})
    assert response.status_code == 500
    assert response.json() == {"error": "internal error (RuntimeError); see the server log"}
    assert "Traceback" not in response.text and "secret" not in response.text


@pytest.mark.parametrize("name", ["../evil", "..", "a/b", "Evil", "x", "evil.yaml", "_hidden", "a" * 65])
def test_path_traversal_and_bad_names_are_refused(client, library_copy, name):
    body = motion_body(client, "placeholder")
    body["name"] = name
    response = client.post("/api/library", json=body)
    assert response.status_code in (422, 403) and response.json()["error"]
    outside = library_copy.parent
    assert sorted(p.name for p in outside.iterdir()) == ["g1"]  # nothing written next to the library


def test_traversal_in_urls(client):
    for url in ["/api/library/..%2F..%2Fetc%2Fpasswd", "/api/library/../../etc/passwd",
                "/api/library/Face_Wave", "/static/../conftest.py", "/static/..%2F..%2Fsettings.py"]:
        response = client.get(url)
        assert response.status_code in (404, 422), url


def test_a_symlink_out_of_the_library_is_never_written(client, library_copy, tmp_path):
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "sneaky.yaml").write_text((library_copy / "face_wave.yaml").read_text().replace(
        "name: face_wave", "name: sneaky"))
    (library_copy / "sneaky.yaml").symlink_to(outside / "sneaky.yaml")
    client.app.state.session.res.library.reload()
    before = (outside / "sneaky.yaml").read_text()
    response = client.post("/api/library", json=motion_body(client, "sneaky", overwrite=True))
    assert response.status_code == 403 and "outside the library" in response.json()["error"]
    assert (outside / "sneaky.yaml").read_text() == before
