"""SIGTERM ends a run like Ctrl-C: the robot is released, the MCAP closes readable, results are written."""

from __future__ import annotations

import json
import os
import signal
import time
from dataclasses import dataclass

import pytest
from omegaconf import OmegaConf

from emopose.app import run
from emopose.resources import Run
from emopose.stop_signals import Terminated, exit_status, sigterm_interrupts
from tests.conftest import compose_config

RELEASED: list[bool] = []


@dataclass
class StopsMidway:
    """A long job that is sent SIGTERM while the robot streams and the recorder is open."""

    def __call__(self, run: Run) -> dict:
        loop = run.session.open()
        loop.tick()
        run.session.write("/test/marker", {"before": "sigterm"})
        backend_close = run.resources.backend.close
        run.resources.backend.close = lambda: (RELEASED.append(True), backend_close())[1]
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(10)  # the signal interrupts this sleep
        raise AssertionError("SIGTERM did not interrupt the job")


def read_every_message(path) -> list[tuple[str, dict]]:
    from mcap.reader import make_reader

    with open(path, "rb") as f:
        return [(channel.topic, json.loads(message.data))
                for _, channel, message in make_reader(f).iter_messages()]


def test_sigterm_releases_the_robot_closes_the_recording_and_writes_results(tmp_path):
    cfg = compose_config(["+experiment=plan", "planner=keyword"])
    OmegaConf.update(cfg, "job", {"_target_": f"{__name__}.StopsMidway"}, merge=False)
    RELEASED.clear()
    with pytest.raises(Terminated) as stopped, sigterm_interrupts():
        run(cfg, tmp_path)
    assert exit_status(stopped.value) == 143
    assert RELEASED == [True]  # the backend was closed (the robot handed back) on the way out
    messages = read_every_message(tmp_path / "session.mcap")  # the official reader: the footer is there
    assert ("/test/marker", {"before": "sigterm"}) in messages
    results = json.loads((tmp_path / "results.json").read_text())
    assert results["interrupted"] and results["signal"] == "SIGTERM" and results["job"] == "StopsMidway"
    assert "SIGTERM" in (tmp_path / "results.md").read_text()


def test_only_the_first_sigterm_interrupts_and_the_handler_is_restored():
    before = signal.getsignal(signal.SIGTERM)
    with sigterm_interrupts():
        with pytest.raises(Terminated):
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(10)
        os.kill(os.getpid(), signal.SIGTERM)  # a second one while releasing: ignored, no exception
        time.sleep(0.05)
    assert signal.getsignal(signal.SIGTERM) is before
