"""The spoken audio is in the recording (issue 31): with TTS on, a session's /speech/audio holds the played
clip's PCM16 samples in chunks at their play-clock time, /speech/said the clip's text and start, and every
message of every channel validates against its typed schema."""

from __future__ import annotations

import base64
from pathlib import Path

import jsonschema
import pytest
from mcap.reader import make_reader

from emopose import app
from emopose.recording import recording_start_ns
from emopose.speech.audio_channel import CHUNK_S, SpeechRecording
from emopose.speech.clip import SpeechClip
from emopose.speech.wav import read_pcm, write_wav
from tests.conftest import compose_config
from tests.recording.conftest import PLAN, every_message


@pytest.fixture(scope="module")
def spoken_recording(tmp_path_factory) -> Path:
    run_dir = tmp_path_factory.mktemp("plan_tts")
    app.run(compose_config([*PLAN, "backend=dry_run", "tts=espeak", f"tts.audio_dir={run_dir / 'tts'}"]),
            run_dir)
    return run_dir / "session.mcap"


def test_every_channel_of_a_spoken_session_validates_against_its_schema(spoken_recording):
    validators = {}
    for topic, schema, _, payload in every_message(spoken_recording):
        validators.setdefault(topic, jsonschema.Draft202012Validator(schema))
        errors = [e.message for e in validators[topic].iter_errors(payload)]
        assert not errors, f"{topic}: {errors[:3]}"
    assert {"/speech/audio", "/speech/said", "/speech/timeline"} <= set(validators)


def test_the_audio_channel_holds_the_clip_as_heard(spoken_recording):
    with spoken_recording.open("rb") as f:
        start_ns = recording_start_ns(make_reader(f))
    rows: dict[str, list] = {}
    for topic, _, stamp, payload in every_message(spoken_recording):
        rows.setdefault(topic, []).append((stamp, payload))
    (_, said), (_, timeline) = rows["/speech/said"][0], rows["/speech/timeline"][0]
    chunks = [payload for _, payload in rows["/speech/audio"]]
    assert said["text"] == timeline["text"] and said["audio"] is True
    assert said["t"] == pytest.approx(timeline["speech_start"], abs=1e-6)  # heard when the gestures expect
    for stamp, chunk in rows["/speech/audio"]:
        assert chunk["t"] == pytest.approx((stamp - start_ns) / 1e9, abs=1e-6)  # logged when it is heard
        assert chunk["t"] == pytest.approx(said["t"] + chunk["offset_s"], abs=1e-6)
    pcm = b"".join(base64.b64decode(c["data"]) for c in chunks)
    rate = chunks[0]["sample_rate"]
    assert len(pcm) / 2 / rate == pytest.approx(said["duration_s"], abs=1e-3)
    assert [c["offset_s"] for c in chunks] == pytest.approx([k * CHUNK_S for k in range(len(chunks))])


def test_a_clip_without_audio_is_said_and_a_broken_wav_is_only_said(tmp_path):
    written: list[tuple[str, float, dict]] = []
    record = SpeechRecording(lambda topic, at, payload: written.append((topic, at, payload)))
    record(SpeechClip("Hello.", 0.8), 3.0)  # tts=none: an estimated clip, no samples
    broken = tmp_path / "broken.wav"
    broken.write_bytes(b"not a wav")
    record(SpeechClip("Hi.", 0.5, audio_path=broken), 4.0)
    assert [(topic, at) for topic, at, _ in written] == [("/speech/said", 3.0), ("/speech/said", 4.0)]
    wav = write_wav(tmp_path / "one.wav", b"\x01\x00" * 16000, 16000)  # 1 s at 16 kHz: two chunks
    record(SpeechClip("One.", 1.0, audio_path=wav), 5.0)
    audio = [(at, p) for topic, at, p in written if topic == "/speech/audio"]
    assert [at for at, _ in audio] == [5.0, 5.5]
    assert b"".join(base64.b64decode(p["data"]) for _, p in audio) == read_pcm(wav)
