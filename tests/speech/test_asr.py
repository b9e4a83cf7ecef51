"""ASR through litellm.transcription against a local OpenAI-compatible server (real HTTP)."""

from __future__ import annotations

import pytest
from fake_audio_server import FakeAudioServer, wav_bytes

from emopose.speech.asr import ASRError, LitellmTranscriber, TypedText


@pytest.fixture
def audio_file(tmp_path):
    path = tmp_path / "utterance.wav"
    path.write_bytes(wav_bytes(0.5, rate=16000))
    return path


def test_audio_file_is_posted_and_transcribed(audio_file):
    with FakeAudioServer(transcript="Where is the robot arm?") as server:
        asr = LitellmTranscriber(model="openai/whisper-1", api_base=server.url, api_key="sk-test",
                                 language="en")
        assert asr.utterance(audio=audio_file) == "Where is the robot arm?"
    path, headers, body = server.requests[0]
    assert path == "/v1/audio/transcriptions"
    assert headers["Content-Type"].startswith("multipart/form-data")
    assert b"whisper-1" in body and b"utterance.wav" in body and wav_bytes(0.5, rate=16000)[:44] in body
    assert asr.last_latency_s is not None


def test_typed_text_wins_over_audio(audio_file):
    asr = LitellmTranscriber(api_base="http://127.0.0.1:9/v1", api_key="sk-test")
    assert asr.utterance(text="  hello there ", audio=audio_file) == "hello there"


def test_server_error_names_the_config_keys(audio_file):
    with FakeAudioServer() as server:
        server.status = 400
        asr = LitellmTranscriber(api_base=server.url, api_key="sk-test")
        with pytest.raises(ASRError, match="asr.api_base"):
            asr.transcribe(audio_file)


def test_missing_or_unsupported_audio_is_refused(tmp_path):
    asr = LitellmTranscriber(api_key="sk-test")
    with pytest.raises(ASRError, match="does not exist"):
        asr.transcribe(tmp_path / "absent.wav")
    text_file = tmp_path / "notes.txt"
    text_file.write_text("hello")
    with pytest.raises(ASRError, match="suffix"):
        asr.transcribe(text_file)


def test_asr_none_passes_typed_text_and_refuses_audio(audio_file):
    asr = TypedText()
    assert asr.utterance(text="Welcome!") == "Welcome!"
    with pytest.raises(ASRError, match="asr=litellm"):
        asr.utterance(audio=audio_file)
    with pytest.raises(ASRError, match="no utterance"):
        asr.utterance()
