"""Pose Studio's keyframe times over the API: the check follows them, a timing the speed bound forbids is
refused (check, perform, save) with the time and the joint, and a save writes them as `times:`."""

from __future__ import annotations

import pytest
import yaml


def frames(client) -> list[list[float]]:
    rest = client.get("/api/library").json()["neutral_pose"]
    up = list(rest)
    up[7], up[8] = -0.9, -0.5  # the right arm raised forward-out: clean at every intensity
    return [rest, up, up, rest]


def test_the_check_follows_the_keyframe_times(client):
    body = {"keyframes": frames(client), "times": [0.0, 0.5, 2.0, 2.5]}
    report = client.post("/api/studio/check", json=body).json()
    assert report["times_declared"] and report["keyframe_times"] == [0.0, 0.5, 2.0, 2.5]
    assert report["duration"] == 2.5 and len(report["samples"]) == 126 and report["can_save"]
    assert report["samples"][25] == pytest.approx(report["samples"][100], abs=1e-4)  # held from 0.5 to 2 s
    even = client.post("/api/studio/check", json={"keyframes": body["keyframes"], "duration": 2.5}).json()
    assert not even["times_declared"] and even["keyframe_times"] == pytest.approx([0.0, 2.5 / 3, 5 / 3, 2.5])


def test_bad_times_are_a_clear_422(client):
    bad = client.post("/api/studio/check", json={"keyframes": frames(client), "times": [0.0, 0.9, 0.5, 1.0]})
    assert bad.status_code == 422 and "times" in bad.text and "K2 at 0.5 s must come at least" in bad.text


def test_a_timing_too_fast_is_refused_with_its_time_and_joint(client, library_copy):
    body = {"keyframes": frames(client), "times": [0.0, 0.06, 1.0, 1.5]}
    report = client.post("/api/studio/check", json=body).json()
    assert not report["can_save"] and len(report["timing_faults"]) == 1
    assert "K1 at 0.06 s" in report["problems"][0] and "right_shoulder_pitch_joint" in report["problems"][0]
    performed = client.post("/api/studio/perform", json=body)
    assert performed.status_code == 422 and "K1 at 0.06 s" in performed.text
    save = {"name": "raise_fast", "class": "welcoming", "description": "raised too fast", **body}
    refused = client.post("/api/library", json=save)
    assert refused.status_code == 422 and "keyframe times too fast" in refused.json()["error"]
    assert not (library_copy / "raise_fast.yaml").exists()


def test_a_save_writes_the_times_and_the_library_serves_them(client, library_copy):
    save = {"name": "raise_timed", "class": "welcoming", "description": "raised quickly, lowered slowly",
            "keyframes": frames(client), "times": [0.0, 0.5, 2.0, 2.5]}
    assert client.post("/api/library", json=save).status_code == 201
    written = yaml.safe_load((library_copy / "raise_timed.yaml").read_text())
    assert written["times"] == [0.0, 0.5, 2.0, 2.5] and "duration" not in written
    entry = client.get("/api/library/raise_timed").json()
    assert entry["times"] == [0.0, 0.5, 2.0, 2.5]
    listed = next(e for e in client.get("/api/library").json()["entries"] if e["name"] == "raise_timed")
    assert listed["duration"] == 2.5
