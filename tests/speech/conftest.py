"""Speech fixtures: a real espeak-ng synthesizer writing into a temporary audio folder."""

from __future__ import annotations

import pytest

from emopose.speech.espeak import EspeakSynthesizer


@pytest.fixture(scope="session")
def espeak(tmp_path_factory) -> EspeakSynthesizer:
    return EspeakSynthesizer(voice="en-us", rate=165, pitch=50, audio_dir=str(tmp_path_factory.mktemp("tts")))
