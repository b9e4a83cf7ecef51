"""serve on the G1 (#33): backend=g1 player=g1 against the fake robot over real DDS, turns over the HTTP API;
the fake robot receives the chest light's states in order, the reply's audio, and stop play on an interrupt.

The documented sequence (emopose/turn/state_light.py, emopose/web/voice_io.py): listening when the session
opens, thinking from the request until the audio starts (no green flicker while the reply is synthesized),
speaking while it plays, listening again, off when serve closes. Asserted on the fake robot's log (colours,
order, bytes), never on wall-clock bounds.
"""

from __future__ import annotations

import base64
import signal
import time

import pytest

from emopose.backends.g1.voice import robot_pcm
from tests.robot.g1_light_helpers import light_states, private_fake_robot, served, wait_until

TEXT = "Welcome to the lab! The robot arm is over there."
LONG = ("Welcome to the lab! This is a long introduction to everything we build here, from the arms to the "
        "voice, and it goes on for quite a while so that it can be interrupted.")


@pytest.fixture
def robot(tmp_path):
    with private_fake_robot(tmp_path) as fake:
        yield fake


@pytest.mark.slow
def test_one_served_turn_lights_thinking_speaking_listening_and_streams_its_audio(tmp_path, robot):
    with served(tmp_path, robot) as (client, run, player):
        turn = client.post("/api/say", json={"text": TEXT}).json()
        wait_until(lambda: player.clips and not player.playing(run.resources.clock), "the reply")
        wait_until(lambda: light_states(robot)[-1:] == ["listening"], "listening after the reply")
    assert light_states(robot) == ["listening", "thinking", "speaking", "listening", "off"]
    stream_id, total, _, sound_start = player.clips[-1]
    assert turn["reply"] == TEXT and turn["speech_start"] == pytest.approx(sound_start)  # the robot's
    chunks = [r for r in robot.entries("voice_chunk") if r["stream_id"] == stream_id]
    assert [r["offset"] for r in chunks] == list(range(0, total, player.chunk_bytes))  # in order, all
    received = b"".join(base64.b64decode(r["pcm"]) for r in chunks)
    assert received == robot_pcm(player.clip.audio_path) and player.last_sink == "g1"


@pytest.mark.slow
def test_an_interrupt_over_the_api_stops_the_robots_stream_and_the_light_listens(tmp_path, robot):
    with served(tmp_path, robot) as (client, run, player):
        client.post("/api/say", json={"text": LONG})
        wait_until(lambda: len(robot.entries("voice_chunk")) >= 5, "five chunks")
        stream_id, total, _, _ = player.clips[-1]
        assert client.post("/api/interrupt", json={}).status_code == 200
        wait_until(lambda: robot.entries("voice_stop"), "stop play")
        wait_until(lambda: light_states(robot)[-1:] == ["listening"], "listening after the interrupt")
        time.sleep(0.3)  # a chunk still in flight would now be in the log
    log = robot.entries()
    stop_at = next(i for i, r in enumerate(log) if r["kind"] == "voice_stop")
    chunks = [i for i, r in enumerate(log) if r["kind"] == "voice_chunk"]
    assert log[stop_at]["stream_id"] == stream_id and max(chunks) < stop_at  # nothing after the stop
    assert len(chunks) < total / player.chunk_bytes  # the reply was cut
    assert light_states(robot) == ["listening", "thinking", "speaking", "listening", "off"]


@pytest.mark.slow
def test_a_robot_fault_turns_the_light_red_until_serve_closes(tmp_path, robot):
    with served(tmp_path, robot) as (_, run, _):
        robot.proc.send_signal(signal.SIGUSR1)  # rt/lowstate stops, the voice service still answers
        wait_until(lambda: light_states(robot)[-1:] == ["fault"], "the fault light")
        assert "lowstate" in str(run.resources.backend.failure)
    assert light_states(robot) == ["listening", "fault", "off"]
