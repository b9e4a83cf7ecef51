"""Pose Studio over the API: checks before saving, the save round trip, the live library.

A motion saved through the API is resolvable and executable on the very next request, with no
restart: MotionLibrary.save reloads and the resolver and guide read the live library.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
import yaml

from tests.web.conftest import SHIPPED
from tests.web.test_api import motion_body, wait_for
from tests.web.test_cue_outcomes import REACH_IN, REST


# -- Pose Studio -----------------------------------------------------------------------------------
def test_studio_check_builds_the_50hz_trajectory_with_the_duration_rule(client):
    library = client.get("/api/library").json()
    rest = library["neutral_pose"]
    raised = list(rest)
    raised[7] = -0.9
    report = client.post("/api/studio/check", json={"keyframes": [rest, raised, raised, rest]}).json()
    assert report["default_duration"] == pytest.approx(1.0)  # clip(0.3 * 3, 1, 5)
    assert len(report["samples"]) == 51 and len(report["samples"][0]) == 14 and report["dt"] == 0.02
    assert [c["intensity"] for c in report["levels"]] == [1, 2, 3, 4, 5] and report["can_save"]
    timed = client.post("/api/studio/check", json={"keyframes": [rest, raised, rest], "duration": 2.5}).json()
    assert timed["explicit_duration"] and len(timed["samples"]) == 126
    assert len(report["stick"]) >= 10 and set(report["stick"][0]) == {"front", "side"}


def test_studio_checks_the_start_poses_a_motion_can_meet(client):
    """A hands-on-heart draft (the library's, its interior 6 % nearer its first keyframe) passes from rest but
    collides at intensity 4 after neutral_ready's held end pose: the check says so (a warning, with what it
    checked) instead of passing it silently."""
    heart = np.array(client.get("/api/library/hands_on_heart").json()["keyframes"])
    heart[1:-1] = heart[0] + 0.94 * (heart[1:-1] - heart[0])
    report = client.post("/api/studio/check", json={"keyframes": heart.tolist()}).json()
    assert report["can_save"] and all(c["ok"] for c in report["levels"])  # from rest
    ready = [c for c in report["starts"] if "neutral_ready" in c["start"]]
    assert ready and ready[0]["failed_levels"] == [4] and "clearance" in ready[0]["reason"]
    assert any("neutral_ready" in w and "intensity 4" in w for w in report["warnings"])
    assert report["checked"].startswith("intensities 1-5 from rest and from ") and report["check_ms"] > 0


def test_studio_shows_checks_and_saves_the_stroke(client, library_copy):
    rest = client.get("/api/library").json()["neutral_pose"]
    up, further = list(rest), list(rest)
    up[7], further[7] = -0.9, -1.1
    frames = [rest, up, further, up, rest]
    auto = client.post("/api/studio/check", json={"keyframes": frames}).json()
    assert auto["stroke"] == [2, 2] and not auto["stroke_declared"]  # default: the largest excursion
    declared = client.post("/api/studio/check", json={"keyframes": frames, "stroke": [1, 3]}).json()
    assert declared["stroke"] == [1, 3] and declared["stroke_declared"]
    bad = client.post("/api/studio/check", json={"keyframes": frames, "stroke": [0, 4]})
    assert bad.status_code == 422 and "stroke [0, 4] must satisfy 1 <= start <= end <= 3" in bad.text
    body = {"name": "reach_twice", "class": "welcoming", "description": "reaches forward twice",
            "keyframes": frames, "stroke": [1, 3]}
    assert client.post("/api/library", json=body).status_code == 201
    assert client.get("/api/library/reach_twice").json()["stroke"] == [1, 3]
    assert yaml.safe_load((library_copy / "reach_twice.yaml").read_text())["stroke"] == [1, 3]


def test_studio_preview_without_mujoco_falls_back_to_the_stick_figure(client):
    rest = client.get("/api/library").json()["neutral_pose"]
    preview = client.post("/api/studio/preview",
                          json={"keyframes": [rest] * 3, "camera": "head", "frames": 5}).json()
    assert preview["frames"] == [] and preview["fallback"] == "stick" and len(preview["times"]) == 5
    assert client.post("/api/studio/preview",
                       json={"keyframes": [rest] * 3, "camera": "../x"}).status_code == 422


def test_studio_refuses_a_colliding_or_out_of_limit_motion(client, library_copy):
    rest = client.get("/api/library").json()["neutral_pose"]
    inward = list(rest)
    inward[7], inward[8] = -0.5, 0.9  # right upper arm swung into the torso
    body = {"name": "hug_torso", "class": "comforting", "description": "collides",
            "keyframes": [rest, inward, rest]}
    report = client.post("/api/studio/check", json={"keyframes": body["keyframes"]}).json()
    assert not report["can_save"] and "self-collision" in report["problems"][0]
    refused = client.post("/api/library", json=body)
    assert refused.status_code == 422 and "self-collision" in refused.json()["error"]
    beyond = list(rest)
    beyond[3] = 3.0  # left elbow past its 2.0944 rad limit
    refused = client.post("/api/library", json={**body, "keyframes": [rest, beyond, rest]})
    assert refused.status_code == 422 and "left_elbow_joint" in refused.json()["error"]
    assert not (library_copy / "hug_torso.yaml").exists()


def test_save_round_trip_with_backup_and_overwrite(client, library_copy):
    shipped_before = sorted(p.name for p in SHIPPED.iterdir())
    body = motion_body(client, "wave_test_variant")
    saved = client.post("/api/library", json=body)
    assert saved.status_code == 201, saved.text
    assert saved.json()["file"] == "g1/wave_test_variant.yaml" and saved.json()["backup"] is None
    assert (library_copy / "wave_test_variant.yaml").is_file()
    assert client.get("/api/library/wave_test_variant").json()["keyframes"] == body["keyframes"]

    again = client.post("/api/library", json=body)
    assert again.status_code == 409 and "overwrite" in again.json()["error"]
    body["keyframes"][1][13] += 0.05
    replaced = client.post("/api/library", json={**body, "overwrite": True})
    assert replaced.status_code == 201 and replaced.json()["replaced"]
    backup = library_copy.parent / replaced.json()["backup"]
    assert backup.is_file() and "wave_test_variant" in backup.read_text()
    assert not list(library_copy.glob(".*.tmp"))  # the atomic write left no temporary file behind
    assert client.get("/api/library/wave_test_variant").json()["keyframes"] == body["keyframes"]
    assert sorted(p.name for p in SHIPPED.iterdir()) == shipped_before  # the shipped library is untouched


def test_a_saved_variant_resolves_and_runs_on_the_next_request(client):
    from emopose.planners.chat.guide import library_guide

    version = client.get("/api/library").json()["version"]
    assert client.post("/api/resolve",
                       json={"class": "welcoming", "variant": "wave_test_variant"}).json()["rule"] \
        == "class_default"
    assert client.post("/api/library", json=motion_body(client, "wave_test_variant")).status_code == 201
    resolved = client.post("/api/resolve", json={"class": "welcoming", "variant": "wave_test_variant"}).json()
    assert resolved["resolved"] == "wave_test_variant" and resolved["rule"] == "exact"
    assert resolved["library_version"] == version + 1
    res = client.app.state.session.res
    assert "wave_test_variant" in library_guide(res.library)  # the planners' guide, regenerated
    turn = client.post("/api/gesture", json={"name": "wave_test_variant"}).json()
    assert turn["cues"][0]["resolved"] == "wave_test_variant" and turn["cues"][0]["rule"] == "exact"
    assert wait_for(lambda: any(e.kind == "started" and e.name == "wave_test_variant"
                                for e in res.sequencer.events))


def test_studio_refuses_a_motion_that_collides_only_at_high_intensity(client, library_copy):
    """Clean at intensities 1-3, into the torso at 4-5: the planner may ask for 5, so it is not saved."""
    rest = client.get("/api/library").json()["neutral_pose"]
    inward = list(rest)
    inward[7], inward[8] = -0.5, 0.0
    keyframes = [rest, inward, rest]
    report = client.post("/api/studio/check", json={"keyframes": keyframes}).json()
    assert [c["ok"] for c in report["levels"]] == [True, True, True, False, False]
    assert not report["can_save"] and any("intensity 5" in p for p in report["problems"])
    refused = client.post("/api/library", json={"name": "reach_in", "class": "comforting",
                                                "description": "collides when strong",
                                                "keyframes": keyframes})
    assert refused.status_code == 422 and "self-collision at intensity 4" in refused.json()["error"]
    assert not (library_copy / "reach_in.yaml").exists()


def test_an_out_of_limits_motion_names_the_offending_joint_its_value_and_its_limit(client):
    rest = client.get("/api/library").json()["neutral_pose"]
    beyond = list(rest)
    beyond[10] = 3.0  # right elbow, past its limit (not the first joint of the list)
    body = {"name": "elbow_over", "class": "comforting", "description": "too far",
            "keyframes": [rest, beyond, rest]}
    error = client.post("/api/library", json=body).json()["error"]
    assert error.count("motion 'elbow_over'") == 1, error  # the prefix is said once
    assert "right_elbow_joint = 3.000 rad in keyframe 1 (allowed" in error and "left_shoulder" not in error


def test_perform_runs_the_edited_draft_not_the_saved_motion(client):
    """The Studio's button sends the keyframes on screen; the library entry of that name is not what runs."""
    saved = client.get("/api/library/face_wave").json()
    draft = [list(k) for k in saved["keyframes"]]
    draft[1][13] += 0.2  # an edit that is not saved
    turn = client.post("/api/studio/perform",
                       json={"keyframes": draft, "class": "welcoming", "intensity": 2}).json()
    cue = turn["cues"][0]
    assert turn["kind"] == "draft" and cue["resolved"] == "studio_draft" and cue["intensity"] == 2
    assert turn["reply"] == ""  # a draft is performed silently
    res = client.app.state.session.res
    assert wait_for(lambda: any(e.kind == "started" and e.name == "studio_draft"
                                for e in res.sequencer.events))
    assert client.get("/api/library").json()["version"] == 1  # the library is untouched


def test_perform_refuses_a_draft_that_collides_at_the_requested_intensity(client):
    rest = client.get("/api/library").json()["neutral_pose"]
    inward = list(rest)
    inward[7], inward[8] = -0.5, 0.0  # clean at 1-3, collides at 4-5
    ok = client.post("/api/studio/perform", json={"keyframes": [rest, inward, rest], "intensity": 3})
    assert ok.status_code == 200
    refused = client.post("/api/studio/perform", json={"keyframes": [rest, inward, rest], "intensity": 5})
    assert refused.status_code == 422 and "self-collision at intensity 5" in refused.json()["error"]


# -- delete and rename (issue 31): the library's usual checks, a backup of every removed file ---------
def test_a_motion_is_renamed_with_a_backup_and_the_usual_checks(client, library_copy):
    assert client.post("/api/library/point_left/rename", json={"new_name": "point_up"}).status_code == 409
    assert client.post("/api/library/point_left/rename", json={"new_name": "Bad Name"}).status_code == 422
    assert client.post("/api/library/palm_stop/rename", json={"new_name": "stop_sign"}).status_code == 409
    renamed = client.post("/api/library/point_left/rename", json={"new_name": "point_aside"})
    assert renamed.status_code == 200, renamed.text
    assert renamed.json()["name"] == "point_aside" and renamed.json()["backup"].endswith(".removed.yaml")
    assert client.get("/api/library/point_left").status_code == 404
    assert client.get("/api/library/point_aside").json()["class"] == "pointing"
    assert not (library_copy / "point_left.yaml").exists() and (library_copy / "point_aside.yaml").is_file()
    assert list((library_copy / ".backup").glob("point_left.v*.removed.yaml"))


def test_a_motion_is_deleted_unless_the_library_needs_it(client, library_copy):
    names = {e["name"]: e["class"] for e in client.get("/api/library").json()["entries"]}
    assert client.post("/api/library/neutral_rest/delete", json={}).status_code == 409  # gestures end there
    assert client.post("/api/library/idle_breathe/delete", json={}).status_code == 409  # a class default
    assert client.post("/api/library/no_such_motion/delete", json={}).status_code == 404
    version = client.get("/api/library").json()["version"]
    deleted = client.post("/api/library/point_up/delete", json={})
    assert deleted.status_code == 200 and deleted.json()["version"] == version + 1
    assert "point_up" not in {e["name"] for e in client.get("/api/library").json()["entries"]}
    assert list((library_copy / ".backup").glob("point_up.v*.removed.yaml"))
    last = [n for n, c in names.items() if c == "doubting" and n != "shrug"]
    for name in last:  # down to the class default: it is the class's last motion and stays
        assert client.post(f"/api/library/{name}/delete", json={}).status_code == 200
    assert client.post("/api/library/shrug/delete", json={}).status_code == 409


def test_a_refusal_names_a_time_and_keyframes_not_a_sample(client):
    report = client.post("/api/studio/check", json={"keyframes": [REST, REACH_IN, REST]}).json()
    reasons = [c["reason"] for c in report["levels"] if not c["ok"]]
    assert reasons, "this draft should collide"
    cited = re.compile(r"at \d+\.\d\d s \((at|between) K\d")
    assert all("sample" not in r and cited.search(r) for r in reasons), reasons


def test_studio_probes_check_the_motion_then_need_the_local_planner(client):
    rest = client.get("/api/library").json()["neutral_pose"]
    raised = list(rest)
    raised[7] = -0.9
    body = {"name": "little_salute", "class": "welcoming", "description": "a small salute; a greeting",
            "keyframes": [rest, raised, rest]}
    bad = client.post("/api/studio/probes", json=body | {"examples": ["ok"]})
    assert bad.status_code == 422 and "examples.0: String should have at least 3 characters" in bad.text
    refused = client.post("/api/studio/probes", json=body | {"examples": ["Ahoy there, sailor!"]})
    assert refused.status_code == 409 and "planner=local" in refused.text  # the web tests plan with keyword


def test_a_motion_saved_in_the_studio_keeps_its_examples(client, library_copy):
    rest = client.get("/api/library").json()["neutral_pose"]
    raised = list(rest)
    raised[7] = -0.9
    body = {"name": "little_salute", "class": "welcoming", "description": "a small salute; a greeting",
            "keyframes": [rest, raised, rest], "examples": ["Ahoy there, sailor!"]}
    assert client.post("/api/library", json=body).status_code == 201
    assert client.get("/api/library/little_salute").json()["examples"] == ["Ahoy there, sailor!"]
