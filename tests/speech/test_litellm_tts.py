"""tts=litellm: hosted audio with estimated word timings, and the espeak fallback (real HTTP)."""

from __future__ import annotations

import logging

import pytest
from fake_audio_server import FakeAudioServer

from emopose.speech.litellm_tts import LitellmSpeech, proportional_words

REPLY = "Welcome to the lab! It weighs 3.5 kg, over there."


def test_hosted_audio_gives_its_duration_and_estimated_words(tmp_path):
    with FakeAudioServer(speech_seconds=2.5) as server:
        tts = LitellmSpeech(model="openai/tts-1", voice="alloy", api_base=server.url, api_key="sk-test",
                            audio_dir=str(tmp_path))
        clip = tts.synthesize(REPLY)
    assert server.requests[0][0] == "/v1/audio/speech" and b'"response_format":"wav"' in server.requests[0][2]
    assert clip.estimated and clip.duration_s == pytest.approx(2.5) and clip.audio_path.exists()
    starts = [w.start_s for w in clip.words]
    assert starts == sorted(starts) and starts[0] >= 0 and starts[-1] <= 2.5
    assert clip.onset_at_char(REPLY.index("kg")) > clip.onset_at_char(REPLY.index("3.5"))


def test_a_keyless_local_server_is_reached_without_a_key(tmp_path, monkeypatch):
    monkeypatch.delenv("OPENAI_API_KEY", raising=False)
    with FakeAudioServer(speech_seconds=1.0) as server:
        tts = LitellmSpeech(model="openai/tts-1", api_base=server.url, audio_dir=str(tmp_path))
        clip = tts.synthesize("Hello there.")
    assert server.requests and not clip.audio_path.name.startswith("espeak")
    assert clip.duration_s == pytest.approx(1.0)  # the server's audio, not the espeak fallback


def test_hosted_failure_falls_back_to_espeak_with_a_warning(tmp_path, caplog):
    with FakeAudioServer() as server:
        server.status = 401
        tts = LitellmSpeech(model="openai/tts-1", api_base=server.url, api_key="sk-test",
                            audio_dir=str(tmp_path))
        with caplog.at_level(logging.WARNING, logger="emopose.speech.litellm_tts"):
            clip = tts.synthesize(REPLY)
    assert not clip.estimated and clip.words and clip.duration_s > 1.0  # the local engine's true timings
    assert "falling back to espeak" in caplog.text


def test_empty_reply_needs_no_request(tmp_path):
    tts = LitellmSpeech(api_base="http://127.0.0.1:9/v1", api_key="sk-test", audio_dir=str(tmp_path))
    assert tts.synthesize("  ").duration_s == 0.0


def test_proportional_estimate_spreads_by_characters():
    words = proportional_words("ab cd", 1.0)
    assert [(w.text, w.start_s) for w in words] == [("ab", 0.0), ("cd", 0.6)]
