"""A gesture the sequencer did not perform shows as such on its cue, with the reason (and a named one
the schedule refuses leaves the reply under way alone).

In live mode a turn is published before its gestures start; a later rejection (self-collision at the
gesture's start) or drop (the timeline could not fit it) lands on the published cue and is announced.
"""

from __future__ import annotations

from fastapi.testclient import TestClient

from emopose.web.turns import cue_rows
from tests.conftest import write_motion
from tests.web.conftest import LOCAL
from tests.web.test_api import wait_for

REST = [0.1, 0.12, 0.0, 1.2, 0.0, 0.0, 0.0, 0.1, -0.12, 0.0, 1.2, 0.0, 0.0, 0.0]
REACH_IN = [*REST[:7], -0.5, 0.0, *REST[9:]]  # clean at intensities 1-3, into the torso at 4-5
REACH_ACROSS = [*REACH_IN[:8], 0.5, *REACH_IN[9:]]  # the right arm into the torso at every intensity


def turn_json(events: list[dict]) -> dict:
    """Three records: 0 ran, 1 was handed to the sequencer (command 8), 2 was dropped by the timeline."""
    record = {"class": "welcoming", "variant": "face_wave", "intensity": 3, "confidence": 1.0,
              "trigger": "hi"}
    resolved = {"resolved": "face_wave", "resolved_class": "welcoming", "rule": "exact"}
    release = {"intensity": 3, "release_s": 0.0, "how": "anchor", "dropped": None}
    return {"plan": {"reply": "hi there", "records": [record] * 3}, "resolved": [resolved] * 3,
            "schedule": {"releases": [release, release,
                                      {**release, "dropped": "no room before the next stroke"}]},
            "submitted": {"commands": [{"id": 8, "record": 1}, {"id": 7, "record": 0}]},  # in release order
            "dispatched": {"events": events}}


def test_rejected_and_dropped_gestures_are_marked_on_their_cues_with_the_reason():
    events = [{"t": 0.0, "kind": "started", "name": "face_wave", "command_id": 7, "detail": ""},
              {"t": 0.1, "kind": "rejected", "name": "face_wave", "command_id": 8,
               "detail": "left hand vs torso"}]
    ran, rejected, dropped = cue_rows(turn_json(events))
    assert ran["outcome"] is None and ran["command_id"] == 7
    assert (rejected["outcome"] == {"kind": "rejected", "reason": "left hand vs torso"}
            and rejected["command_id"] == 8)
    assert dropped["outcome"] == {"kind": "dropped", "reason": "no room before the next stroke"}
    assert dropped["command_id"] is None
    events[1] = {**events[1], "kind": "dropped", "detail": "late"}  # any refusal kind, by its event
    assert cue_rows(turn_json(events))[1]["outcome"] == {"kind": "dropped", "reason": "late"}


def test_a_cue_gives_the_intensity_played_and_the_one_the_plan_asked_for():
    data = turn_json([])
    data["schedule"]["releases"][0] = {**data["schedule"]["releases"][0], "intensity": 1}  # softened
    softened, kept, _ = cue_rows(data)
    assert (softened["intensity"], softened["requested_intensity"]) == (1, 3)
    assert (kept["intensity"], kept["requested_intensity"]) == (3, 3)


def test_a_named_gesture_too_strong_to_fit_runs_softened_and_its_cue_says_so(serve_app, library_copy):
    write_motion(library_copy, "reach_in", "comforting", [REST, REACH_IN, REST])
    app, _ = serve_app()  # timeline mode: at 4 and 5 every timing is refused, so the schedule softens it
    with TestClient(app, base_url=LOCAL) as client:
        cue = client.post("/api/gesture", json={"name": "reach_in", "intensity": 5}).json()["cues"][0]
        assert cue["requested_intensity"] == 5 and cue["intensity"] in (1, 2, 3), cue
        assert cue["outcome"] is None

        def logged_cue():
            return next(m for m in client.get("/api/turns").json()["log"] if m["type"] == "turn")["cues"][0]

        assert wait_for(lambda: logged_cue()["stroke_executed_s"] is not None)  # it ran
        assert logged_cue()["outcome"] is None


def test_a_refused_named_gesture_leaves_the_reply_under_way_alone(serve_app, library_copy):
    write_motion(library_copy, "reach_across", "comforting", [REST, REACH_ACROSS, REST])
    app, session = serve_app()  # timeline mode: the schedule drops reach_across at every intensity
    with TestClient(app, base_url=LOCAL) as client:
        said = client.post("/api/say", json={"text": "Welcome to the lab."}).json()
        running = said["cues"][0]["command_id"]
        refused = client.post("/api/gesture", json={"name": "reach_across", "intensity": 3}).json()
        assert refused["cues"][0]["outcome"]["kind"] == "dropped"

        def said_cue():
            return next(m for m in client.get("/api/turns").json()["log"]
                        if m.get("turn_id") == said["turn_id"] and m["type"] == "turn")["cues"][0]

        assert wait_for(lambda: said_cue()["stroke_executed_s"] is not None)  # the reply's gesture ran on
        kinds = [e.kind for e in session.res.sequencer.events if e.command_id == running]
        assert "stopped" not in kinds, kinds


def test_a_gesture_rejected_after_its_turn_was_published_is_shown_rejected(serve_app, library_copy):
    write_motion(library_copy, "reach_in", "comforting", [REST, REACH_IN, REST])
    # The paper's release mode starts the gesture after the turn is published (a timeline may start it in
    # its pre-roll, before publishing, and the outcome is then on the cue from the start).
    app, session = serve_app("pipeline.stages.schedule.mode=anchor")
    with TestClient(app, base_url=LOCAL) as client:
        # published at hand-off
        turn = client.post("/api/gesture", json={"name": "reach_in", "intensity": 5}).json()

        def logged_outcome():
            log = client.get("/api/turns").json()["log"]
            return next(m for m in log if m["type"] == "turn")["cues"][0]["outcome"]

        assert wait_for(lambda: logged_outcome() is not None)
        assert logged_outcome()["kind"] == "rejected" and "vs torso" in logged_outcome()["reason"]
        announced = [m for m in client.get("/api/turns").json()["log"] if m["type"] == "cue_outcome"]
        assert ([(m["turn_id"], m["k"], m["outcome"]["kind"]) for m in announced]
                == [(turn["turn_id"], 0, "rejected")])
        kinds = [e.kind for e in session.res.sequencer.events if e.name == "reach_in"]
        assert "rejected" in kinds and "started" not in kinds


def test_a_named_gesture_is_silent_and_a_narrated_turn_says_so(client):
    gesture = client.post("/api/gesture", json={"name": "face_wave"}).json()
    # the motion's name is not spoken
    assert gesture["reply"] == "" and gesture["speech"]["duration_s"] == 0.0
    spoken = client.post("/api/gesture", json={"name": "face_wave", "text": "Hello there!"}).json()
    assert spoken["reply"] == "Hello there!"
    said = client.post("/api/say", json={"text": "Welcome to the lab."}).json()
    assert said["narrated"] and not gesture["narrated"]  # the keyword planner repeats the user's text
