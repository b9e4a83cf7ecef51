"""Speech over the API, through the composed serve experiment: spoken replies out, spoken utterances in.

Speech input is `asr=litellm asr.api_base=...` exactly as on the command line, against a local
OpenAI-compatible /audio/transcriptions stub with real HTTP and no provider key: the recording the page
posts goes to the stub through litellm, and its transcript becomes an ordinary turn.
"""

from __future__ import annotations

import pytest
from fastapi.testclient import TestClient

from tests.speech.fake_audio_server import FakeAudioServer, wav_bytes
from tests.web.conftest import LOCAL

UPLOAD = "/api/utterance/audio"
WAV = {"Content-Type": "audio/wav"}


@pytest.fixture
def transcriber():
    with FakeAudioServer(transcript="Welcome to the lab!") as server:
        yield server


@pytest.fixture
def listening(serve_app, transcriber, monkeypatch):
    """A client of the server composed with asr=litellm pointed at the stub (keyless, like a local
    whisper)."""
    monkeypatch.delenv("OPENAI_API_KEY", raising=False)
    app, _ = serve_app("asr=litellm", f"asr.api_base={transcriber.url}")
    with TestClient(app, base_url=LOCAL) as client:
        yield client


def test_asr_litellm_offers_speech_input(listening):
    assert listening.get("/api/info").json()["asr"] is True
    with listening.websocket_connect("ws://127.0.0.1/ws") as ws:
        assert ws.receive_json()["asr"] is True  # the page shows its microphone from this hello


def test_a_posted_recording_becomes_a_turn(listening, transcriber):
    audio = wav_bytes(0.5, rate=16000)
    turn = listening.post(UPLOAD, content=audio, headers=WAV).json()
    assert turn["type"] == "turn" and turn["kind"] == "say" and turn["utterance"] == "Welcome to the lab!"
    assert [c["class"] for c in turn["cues"]] == ["welcoming"]
    assert listening.get("/api/turns").json()["log"][-1]["turn_id"] == turn["turn_id"]  # every page hears it
    path, _, body = transcriber.requests[-1]
    assert path == "/v1/audio/transcriptions" and b"utterance.wav" in body and audio[:44] in body


def test_a_failed_or_silent_transcription_is_a_422_and_no_turn(listening, transcriber):
    transcriber.status = 400
    failed = listening.post(UPLOAD, content=wav_bytes(0.2), headers=WAV)
    assert failed.status_code == 422 and "asr.api_base" in failed.json()["error"]
    transcriber.status, transcriber.transcript = 200, "  "
    silent = listening.post(UPLOAD, content=wav_bytes(0.2), headers=WAV)
    assert silent.status_code == 422 and "no recognisable speech" in silent.json()["error"]
    assert listening.get("/api/turns").json()["log"] == []


def test_uploads_are_checked_at_the_edge(listening, transcriber):
    webm = {"Content-Type": "audio/webm"}
    assert listening.post(UPLOAD, content=b"x", headers={"Content-Type": "video/x-evil"}).status_code == 415
    assert listening.post(UPLOAD, content=b"", headers=webm).status_code == 400
    assert listening.post(UPLOAD, content=b"0" * (9 * 1024 * 1024), headers=webm).status_code == 413
    assert transcriber.requests == []  # nothing refused reached the recognizer


def test_without_an_asr_the_upload_says_how_to_enable_it(client):
    assert client.get("/api/info").json()["asr"] is False
    refused = client.post(UPLOAD, content=wav_bytes(0.2), headers=WAV)
    assert refused.status_code == 409 and "asr=litellm" in refused.json()["error"]


def test_audio_is_served_only_for_known_turns(client):
    assert client.get("/api/audio/999").status_code == 404
    assert client.get("/api/audio/..%2F..%2Fetc%2Fpasswd").status_code in (404, 422)


def test_spoken_reply_audio_is_served(serve_app):
    app, _ = serve_app("tts=espeak")
    with TestClient(app, base_url=LOCAL) as client:
        turn = client.post("/api/say", json={"text": "Hello there!"}).json()
        assert turn["speech"]["audio"] and not turn["speech"]["estimated"]
        audio = client.get(turn["speech"]["audio"])
    assert audio.status_code == 200 and audio.content[:4] == b"RIFF"
