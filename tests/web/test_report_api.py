"""The page's session report (issue 31): /api/info names this session's recording and the command that
reports on it; POST /api/report runs that report on the live recording in a child process (never in the
server's, which runs the control loop) and serves its table and figures by name, nothing else."""

from __future__ import annotations

import subprocess

import pytest
from fastapi.testclient import TestClient

import emopose.web.report as report_module
from tests.web.conftest import LOCAL
from tests.web.test_api import wait_for

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.mark.slow  # the child process draws the figures: ~15 s on a loaded 2-core machine
def test_the_report_of_the_live_recording_is_made_in_a_child_process(serve_app, monkeypatch):
    children, run = [], subprocess.run
    monkeypatch.setattr(report_module.subprocess, "run",
                        lambda command, **kw: children.append(command) or run(command, **kw))
    app, session = serve_app("run.record=true")
    recording = (session.run.session.run_dir / "session.mcap").resolve()
    with TestClient(app, base_url=LOCAL) as client:
        info = client.get("/api/info").json()["report"]
        assert info["recording"] == str(recording)
        assert info["command"] == f"python -m emopose +experiment=recording_report recording={recording}"
        client.post("/api/say", json={"text": "Welcome! The robot arm is over there."})
        size = recording.stat().st_size
        assert wait_for(lambda: recording.stat().st_size > size, timeout_s=10)  # the turn's chunk is on disk
        made = client.post("/api/report", json={})
        assert made.status_code == 200, made.text
        report = made.json()
        assert children and children[0][1:3] == ["-m", "emopose.web.report"]
        assert {"turn_000.png", "loop_health.png"} <= set(report["figures"])
        assert report["markdown"].startswith("# Recording report") and "Welcome!" in report["markdown"]
        assert client.get("/api/report/results.md").text == report["markdown"]
        assert client.get("/api/report/turn_000.png").content.startswith(PNG)
        assert client.get("/api/report/session.mcap").status_code == 404  # only the report's own files
        assert client.get("/api/report/..%2Fsession.mcap").status_code == 404


def test_a_session_that_records_nothing_says_so(client):
    assert client.get("/api/info").json()["report"]["command"] is None
    refused = client.post("/api/report", json={})
    assert refused.status_code == 409 and "run.record=false" in refused.json()["error"]
