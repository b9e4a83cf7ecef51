"""Helpers for the chest light and voice tests against the fake G1 (tests/robot/test_g1_*.py, tests/tour): a
fake robot on a private DDS domain, the light states it was asked to show, a planner slow enough to see,
and serve on the fake G1."""

from __future__ import annotations

import json
import random
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from emopose.backends.g1.chest_light import COLOURS
from emopose.backends.g1.voice import VOICE_API_SET_RGB_LED
from tests.backends.g1.conftest import FakeRobot, require_dds
from tests.web.conftest import LOCAL, compose_serve, copy_library

STATE_OF = {rgb: state for state, rgb in COLOURS.items()}
# A loaded CI machine may stall the loop past the deadman's 100 ms: a fault is not what is tested here.
LOADED_MACHINE = ("backend.deadman_ms=2000", "backend.lowstate_loss_ms=2000")


@contextmanager
def private_fake_robot(folder: Path, *args: str) -> Iterator[FakeRobot]:
    """A fake G1 on a random DDS domain of its own, stopped afterwards."""
    require_dds()
    fake = FakeRobot(random.SystemRandom().randint(20, 230), folder / "fake.jsonl", list(args))
    try:
        yield fake
    finally:
        fake.stop()


def light_states(robot: FakeRobot) -> list[str]:
    """The states the robot was asked to show (api 1010), in arrival order, repeats of one state folded;
    a colour that is no state's is a KeyError."""
    calls = [r for r in robot.entries("voice") if r["api_id"] == VOICE_API_SET_RGB_LED]
    states = [STATE_OF[(p["R"], p["G"], p["B"])] for p in (json.loads(r["parameter"]) for r in calls)]
    return [s for k, s in enumerate(states) if k == 0 or states[k - 1] != s]


class SlowPlanner:
    """A planner slowed by `seconds` a call, so a line's planning lasts long enough for the light to show
    it (the light reads the state every 0.1 s); everything else is the wrapped planner's."""

    def __init__(self, planner, seconds: float) -> None:
        self.planner, self.seconds = planner, seconds

    def __getattr__(self, name: str):
        return getattr(self.planner, name)

    def plan(self, *args, **kwargs):
        time.sleep(self.seconds)
        return self.planner.plan(*args, **kwargs)


def wait_until(condition, what: str, timeout_s: float = 20.0) -> None:
    deadline = time.monotonic() + timeout_s
    while not condition():
        assert time.monotonic() < deadline, f"{what} did not happen"
        time.sleep(0.02)


@contextmanager
def served(tmp_path: Path, robot: FakeRobot, *overrides: str) -> Iterator[tuple[object, object, object]]:
    """serve as ServeJob builds it (without frames) on the fake G1 (backend=g1 player=g1 tts=espeak), as
    (client, run, player), its planner slowed to 0.6 s a line so "thinking" lasts long enough to be seen;
    serve is closed afterwards."""
    from fastapi.testclient import TestClient

    from emopose.build import build_job, build_run
    from emopose.web.app import create_app
    from emopose.web.live import open_session

    cfg = compose_serve(copy_library(tmp_path), "backend=g1", f"backend.domain_id={robot.domain_id}",
                        "backend.weight_ramp_up_s=0.4", "backend.weight_ramp_down_s=0.4",
                        "backend.release_blend_s=0.2", *LOADED_MACHINE, "player=g1", "player.fallback=none",
                        "player.latency_s=0.0", "tts=espeak", f"tts.audio_dir={tmp_path / 'tts'}",
                        "posture.idle_motion=false", *overrides)
    settings = build_job(cfg).settings
    with build_run(cfg, tmp_path / "run") as run:
        session = open_session(run, settings, render=False)
        try:
            run.session.open().start()
            run.runner.planner = SlowPlanner(run.runner.planner, 0.6)
            with TestClient(create_app(session), base_url=LOCAL) as client:
                wait_until(lambda: light_states(robot)[:1] == ["listening"], "the first light request")
                yield client, run, run.resources.player
        finally:
            session.close()
            run.session.close()
