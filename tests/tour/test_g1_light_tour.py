"""The tour drives the G1's chest light as serve does (#33): a real-time tour with player=g1 against the fake
robot's voice service over real DDS; the light requests (api 1010) it received, in order, and the audio.

Asserted on the fake robot's log (colours, their order, counters), never on wall-clock bounds.
"""

from __future__ import annotations

import logging

import pytest

from emopose.build import build_run
from emopose.tour.camera import camera_for
from emopose.tour.runner import TourRunner
from emopose.tour.scenario_loading import parse_tour
from emopose.tour.sim_base import MujocoBase
from emopose.tour.sim_scene import install_scene
from tests.backends.g1.conftest import FakeRobot
from tests.robot.g1_light_helpers import SlowPlanner, light_states, private_fake_robot
from tests.tour.tour_helpers import small, tour_config


@pytest.fixture
def robot(tmp_path):
    with private_fake_robot(tmp_path) as fake:
        yield fake


def run_tour(tmp_path, robot: FakeRobot, *overrides: str):
    raw = small(stops=small()["stops"][:1])  # one stop: walk 0.6 m, narrate, come to rest
    cfg = tour_config(tmp_path, "planner=keyword", "tts=espeak", f"tts.audio_dir={tmp_path / 'tts'}",
                      "run.clock=monotonic", "player=g1", f"player.domain_id={robot.domain_id}",
                      "player.fallback=none", "player.latency_s=0.0", "posture.idle_motion=false", *overrides)
    with build_run(cfg, tmp_path / "run") as run:
        spec, backend = parse_tour(raw, "test scenario"), run.resources.backend
        install_scene(backend, spec, tmp_path)
        run.session.open().start()  # real time: the loop streams on its thread, as on the G1
        run.runner.planner = SlowPlanner(run.runner.planner, 0.6)
        base = MujocoBase(backend.planar_base)
        base.place(spec.start.pose())
        report = TourRunner(run, spec, base, camera_for(backend)).run()
        return report, run.resources.player


@pytest.mark.slow
def test_a_tour_shows_listening_thinking_speaking_and_ends_with_the_light_off(tmp_path, robot):
    report, player = run_tour(tmp_path, robot)
    assert report.ended_at_rest and not report.aborted and report.stops[0].narration
    states = light_states(robot)
    # walking, the line planned and synthesized (no green flicker before the audio), said; off at the end
    assert states[:3] == ["listening", "thinking", "speaking"] and states[-1] == "off", states
    assert states[3:-1] in ([], ["listening"]), states  # the arms' return to rest may be too short to show
    chunks = robot.entries("voice_chunk")
    assert player.last_sink == "g1" and len(chunks) == player.sender.chunks_sent > 0  # the robot spoke it
    last_chunk = max(r["t"] for r in chunks)
    light_calls = [r for r in robot.entries("voice") if r["api_id"] == 1010]
    assert light_calls[-1]["t"] > last_chunk  # off after the robot has said everything


@pytest.mark.slow
def test_player_light_false_leaves_the_light_alone_on_the_tour(tmp_path, robot):
    report, player = run_tour(tmp_path, robot, "player.light=false")
    assert report.ended_at_rest and player.sender.chunks_sent > 0
    assert light_states(robot) == []


@pytest.mark.slow
def test_a_voice_service_that_never_answers_warns_and_the_tour_goes_on(tmp_path, caplog):
    with private_fake_robot(tmp_path, "--voice-mute") as robot, caplog.at_level(logging.WARNING):
        report, player = run_tour(tmp_path, robot, "player.timeout_s=0.3")
    assert report.ended_at_rest and not report.aborted and report.stops[0].narration  # said, gestured
    assert player.last_sink == "none" and player.sender.chunks_sent == 0  # the documented fallback
    assert light_states(robot)[:1] == ["listening"]  # it asked (the fake logs requests it never answers)
    warnings = [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]
    assert sum("voice service failed (RpcTimeoutError" in w for w in warnings) == 1, warnings
    assert sum(w.startswith("chest light:") for w in warnings) == 1, warnings  # once per run of failures
