"""The robot's microphone stream: the fake G1 streams a WAV over UDP (a local port, and the robot's
multicast group on loopback), RobotMicrophone delivers it unchanged; the playback gate, a silent
group and the utterance cutter, without a robot."""

from __future__ import annotations

import logging
import socket
import time
import wave

import numpy as np
import pytest

from emopose.backends.g1.voice import robot_pcm
from emopose.speech.g1_microphone import MIC_GROUP, RobotMicrophone, Utterances
from emopose.speech.vad import CHUNK_BYTES, VoiceActivity


def free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


@pytest.fixture
def speech_wav(tmp_path):
    path = tmp_path / "visitor.wav"
    with wave.open(str(path), "wb") as out:
        out.setnchannels(1), out.setsampwidth(2), out.setframerate(22050)
        out.writeframes((3000 * np.sin(np.arange(22050) / 7.0)).astype("<i2").tobytes())
    return path


def collect(microphone_args: dict, robot_args: list[str], fake_robot, wav) -> bytes:
    received: list[bytes] = []
    mic = RobotMicrophone(received.append, **microphone_args).start()
    try:
        fake_robot("--mic-wav", str(wav), "--mic-delay", "0.2", *robot_args)
        expected = len(robot_pcm(wav))
        deadline = time.monotonic() + 15.0
        while sum(map(len, received)) < expected and time.monotonic() < deadline:
            time.sleep(0.02)
    finally:
        mic.stop()
    return b"".join(received)


def test_the_fake_robots_microphone_arrives_unchanged_on_a_local_port(fake_robot, speech_wav):
    port = free_port()
    pcm = collect({"group": None, "port": port, "interface_ip": "127.0.0.1"},
                  ["--mic-target", f"127.0.0.1:{port}"], fake_robot, speech_wav)
    assert pcm == robot_pcm(speech_wav)


def test_the_robots_multicast_group_on_loopback(fake_robot, speech_wav):
    port = free_port()
    try:
        RobotMicrophone(lambda pcm: None, group=MIC_GROUP, port=port, interface_ip="127.0.0.1").start().stop()
    except OSError as exc:
        pytest.skip(f"no multicast on loopback here: {exc}")
    pcm = collect({"group": MIC_GROUP, "port": port, "interface_ip": "127.0.0.1"},
                  ["--mic-target", f"{MIC_GROUP}:{port}"], fake_robot, speech_wav)
    assert pcm == robot_pcm(speech_wav)


def test_the_robots_own_playback_is_gated_out():
    delivered, speaking = [], [False]
    mic = RobotMicrophone(delivered.append, group=None, port=free_port(), interface_ip="127.0.0.1",
                          speaking=lambda: speaking[0], tail_s=0.0)
    voice = b"\x10\x00" * 320
    mic._deliver(voice)
    speaking[0] = True
    mic._deliver(voice)
    speaking[0] = False
    mic._deliver(voice)
    assert delivered == [voice, bytes(len(voice)), voice]  # silence of the same length: time stays whole
    assert (mic.received_bytes, mic.muted_bytes) == (3 * len(voice), len(voice))


def test_a_silent_group_warns_once_and_never_raises(caplog):
    mic = RobotMicrophone(lambda pcm: None, group=None, port=free_port(), interface_ip="127.0.0.1",
                          silence_warn_s=0.2)
    with caplog.at_level(logging.WARNING, logger="emopose.speech.g1_microphone"):
        mic.start()
        deadline = time.monotonic() + 5.0
        while not mic.silent and time.monotonic() < deadline:
            time.sleep(0.02)
        mic.stop()
    assert mic.silent and caplog.text.count("is the robot's voice mode on") == 1


def test_utterances_cut_one_wav_per_speech_span(tmp_path):
    loud = (np.full(16000, 4000)).astype("<i2").tobytes()  # 1 s "speech"
    quiet = bytes(32000)  # 1 s silence
    energy = lambda chunk: float(np.abs(np.frombuffer(chunk, "<i2")).mean() > 1000)  # noqa: E731
    heard = []
    cutter = Utterances(VoiceActivity(detector=energy, hang_ms=300), tmp_path, heard.append, pad_s=0.2)
    for pcm in (quiet, loud, quiet):
        for first in range(0, len(pcm), 640):  # 20 ms datagrams, as the robot sends
            cutter.feed(pcm[first:first + 640])
    assert len(heard) == 1
    with wave.open(str(heard[0]), "rb") as audio:
        samples = np.frombuffer(audio.readframes(-1), "<i2")
    assert np.count_nonzero(samples) == 16000  # all of the speech, from 0.2 s before the first speech
    # The VAD scores 512-sample chunks: the first speech chunk starts at 31 * 512 = 15872, the last
    # (partly loud) ends at 63 * 512 = 32256; the WAV runs from 0.2 s (3200 samples) before to that end.
    assert CHUNK_BYTES == 2 * 512 and len(samples) == 32256 - (15872 - 3200)
