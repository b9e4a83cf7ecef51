"""SIGTERM ends a run like Ctrl-C: the robot is released, the MCAP closes readable, results are written,
and the run exits 143 (SIGINT: 130), even when a library swallowed or wrapped the interrupt."""

from __future__ import annotations

import ctypes
import json
import os
import signal
import time
from dataclasses import dataclass

import pytest
from omegaconf import OmegaConf

from emopose.app import run
from emopose.resources import Run
from emopose.stop_signals import Terminated, exit_status, stop_signals_interrupt
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


class SigtermInCtypes:
    """As mujoco's import probes EGL in backend.connect: the SIGTERM handler runs while ctypes converts a
    call's arguments, and ctypes turns the Terminated it raises into a ctypes.ArgumentError."""

    def __call__(self, run: Run) -> dict:
        run.session.open().tick()
        run.session.write("/test/marker", {"before": "sigterm"})

        class SendsSigterm:
            @classmethod
            def from_param(cls, value):
                os.kill(os.getpid(), signal.SIGTERM)
                return ctypes.c_int(value)

        absolute = ctypes.CDLL(None).abs
        absolute.argtypes = [SendsSigterm]
        absolute(-1)
        raise AssertionError("SIGTERM did not interrupt the job")


class ServesUntilStopped:
    """As uvicorn.run in serve: a graceful shutdown on the signal, then a normal return with results."""

    stop_with = signal.SIGTERM

    def __call__(self, run: Run) -> tuple[dict, str]:
        try:
            os.kill(os.getpid(), self.stop_with)
            time.sleep(10)
        except KeyboardInterrupt:  # uvicorn.run catches it, shuts down and returns
            pass
        return {"turns": 3}, "# Served 3 turns"


class ServesUntilSigint(ServesUntilStopped):
    stop_with = signal.SIGINT


def job_config(job: str):
    cfg = compose_config(["+experiment=plan", "planner=keyword"])
    OmegaConf.update(cfg, "job", {"_target_": f"{__name__}.{job}"}, merge=False)
    return cfg


def test_sigterm_releases_the_robot_closes_the_recording_and_writes_results(tmp_path):
    cfg = job_config("StopsMidway")
    (tmp_path / "results.json").write_text('{"completed": true}')  # a finished run's, in a reused directory
    RELEASED.clear()
    with pytest.raises(Terminated) as stopped, stop_signals_interrupt():
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
    with stop_signals_interrupt():
        with pytest.raises(Terminated):
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(10)
        os.kill(os.getpid(), signal.SIGTERM)  # a second one while releasing: ignored, no exception
        time.sleep(0.05)
    assert signal.getsignal(signal.SIGTERM) is before


def test_a_sigterm_that_ctypes_wrapped_ends_the_run_as_sigterm(tmp_path):
    with pytest.raises(Terminated) as stopped, stop_signals_interrupt():
        run(job_config("SigtermInCtypes"), tmp_path)
    assert exit_status(stopped.value) == 143 and isinstance(stopped.value.__cause__, ctypes.ArgumentError)
    assert ("/test/marker", {"before": "sigterm"}) in read_every_message(tmp_path / "session.mcap")
    results = json.loads((tmp_path / "results.json").read_text())
    assert results["interrupted"] and results["signal"] == "SIGTERM" and results["job"] == "SigtermInCtypes"


@pytest.mark.parametrize("job,status", [("ServesUntilStopped", 143), ("ServesUntilSigint", 130)])
def test_a_server_that_shut_down_on_a_signal_keeps_its_results_and_exits_as_stopped(job, status, tmp_path):
    with pytest.raises(KeyboardInterrupt) as stopped, stop_signals_interrupt():
        run(job_config(job), tmp_path)
    assert exit_status(stopped.value) == status
    assert json.loads((tmp_path / "results.json").read_text()) == {"turns": 3}


class ReadsItsResults:
    def __call__(self, run: Run) -> tuple[dict, str]:
        return json.loads((run.resources.run_dir / "results.json").read_text()), "# read"


class Crashes:
    def __call__(self, run: Run) -> tuple[dict, str]:
        raise RuntimeError("the job broke\nover two lines")


def test_a_reused_run_directory_shows_this_run_in_progress_then_its_outcome(tmp_path):
    (tmp_path / "results.json").write_text('{"completed": true}')
    assert run(job_config("ReadsItsResults"), tmp_path) == {"job": "ReadsItsResults", "completed": False,
                                                           "in_progress": True}
    with pytest.raises(RuntimeError):
        run(job_config("Crashes"), tmp_path)
    assert json.loads((tmp_path / "results.json").read_text()) == {
        "job": "Crashes", "completed": False, "error": "the job broke over two lines"}
