"""The serve CLI's edges: a busy port stops it before anything loads (one line, exit 2, results.json), and
a stop signal ends it with the shell's status for that signal (143 SIGTERM, 130 SIGINT) after writing
results that count its turns."""

from __future__ import annotations

import json
import signal
import socket
import subprocess
import sys
import urllib.request

import pytest

from tests.web.browser import served
from tests.web.conftest import copy_library, library_overrides


def post(url: str, body: dict) -> dict:
    request = urllib.request.Request(url, data=json.dumps(body).encode(),
                                     headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(request, timeout=60) as response:
        return json.load(response)


def test_a_second_serve_on_a_busy_port_stops_at_once_in_one_line(tmp_path):
    library = copy_library(tmp_path)
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        done = subprocess.run(
            [sys.executable, "-m", "emopose", "+experiment=serve", "planner=keyword", "job.render=false",
             f"serve.port={port}", f"hydra.run.dir={tmp_path}/run", *library_overrides(library)],
            capture_output=True, text=True, timeout=300)
    errors = [line for line in done.stderr.splitlines() if line.startswith("error:")]
    assert done.returncode == 2 and len(errors) == 1 and f"serve.port={port}" in errors[0], done.stderr
    assert "in use" in errors[0] and "EmoPose UI" not in done.stdout  # no banner pointing elsewhere
    results = json.loads((tmp_path / "run" / "results.json").read_text())
    assert results["completed"] is False and "in use" in results["error"]
    assert not (tmp_path / "run" / "session.mcap").exists()  # the robot was never opened


@pytest.mark.slow  # two real servers
@pytest.mark.parametrize("stop, status", [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_a_stop_signal_sets_the_exit_status_after_the_results(tmp_path, stop, status):
    with served(tmp_path, "job.render=false", stop=stop) as server:
        post(f"{server['base']}/api/say", {"text": "Welcome to the lab!"})
    assert server["process"].returncode == status
    results = json.loads((tmp_path / "run" / "results.json").read_text())
    assert results["turns"] == 1 and results["sources"] == {"model": 1}
