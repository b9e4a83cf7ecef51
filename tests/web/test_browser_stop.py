"""The served CLI stopped with SIGTERM (systemd, docker stop, timeout): the run directory stays whole.

The official mcap reader must read every message of session.mcap (a killed writer leaves no footer:
EndOfFile) and results.json must be written, as with Ctrl-C.
"""

from __future__ import annotations

import json
import signal
import urllib.request

import pytest

from tests.web.browser import get_json, served
from tests.web.test_api import wait_for

pytestmark = pytest.mark.slow


def post_json(url: str, body: dict) -> dict:
    request = urllib.request.Request(url, data=json.dumps(body).encode(), method="POST",
                                     headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(request, timeout=30) as response:
        return json.load(response)


def test_sigterm_while_serving_closes_the_recording_and_writes_results(tmp_path):
    from mcap.reader import make_reader

    with served(tmp_path, stop=signal.SIGTERM, record=True) as server:
        turn = post_json(server["base"] + "/api/say", {"text": "Welcome! The robot arm is over there."})
        assert turn["cues"], turn
        assert wait_for(lambda: get_json(server["base"] + "/api/status")["state"] != "idle", timeout_s=10)
    assert server["process"].returncode == 143, (tmp_path / "server.log").read_text()[-3000:]  # 128 + SIGTERM
    with open(server["run"] / "session.mcap", "rb") as f:
        # every message, to the end
        topics = [channel.topic for _, channel, _ in make_reader(f).iter_messages()]
    assert "/joints/command" in topics and len(topics) > 10
    results = json.loads((server["run"] / "results.json").read_text())
    assert results["turns"] == 1 and results["loop"]["ticks"] > 0
    assert (server["run"] / "results.md").is_file()
