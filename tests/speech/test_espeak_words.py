"""EspeakSynthesizer: audio, T_a from the sample count, and word timings from the engine's events."""

from __future__ import annotations

import random
import threading
import wave

import pytest

from emopose.speech import espeak_lib
from emopose.speech.espeak import EspeakSynthesizer
from emopose.speech.word_events import clean_events

REPLIES = [
    "Welcome to the lab! The robot arm is over there.",
    "It weighs 3.5 kg and costs $20, 50% off.",
    "Hi 👋🏽 there, café ☕! 😀 great news 🎉 yes",
    '"Welcome!" she said — it\'s the robot\'s arm (over there)... Really?',
    "Dr. Smith arrived at 10:30 a.m. on 2024-05-01, e.g. today.",
    "It costs $1,250.75 — about €30 or £25; 1st, 2nd, 3rd place. 100,000 people!",
    "日本語 テキスト and then English words.",
    "well-known state-of-the-art robots, A/B testing, x+y=z & co.\nNew line\there.",
]


def _long_reply() -> str:
    rng = random.Random(7)
    words = ["the", "robot", "arm", "is", "over", "there", "and", "we", "can", "see", "42", "interesting",
             "things", "in", "this", "lab", "today"]
    return " ".join(rng.choice(words) for _ in range(500)) + " FINALWORD."


@pytest.mark.parametrize("reply", [*REPLIES, _long_reply()], ids=[*map(str, range(len(REPLIES))), "long"])
def test_word_timings_monotone_inside_audio_and_on_the_text(espeak, reply):
    clip = espeak.synthesize(reply)
    assert clip.duration_s > 0 and not clip.estimated and clip.words
    starts = [w.start_s for w in clip.words]
    assert starts == sorted(starts)
    assert starts[0] >= 0.0 and starts[-1] <= clip.duration_s
    previous_end = 0
    for word in clip.words:
        assert reply[word.char_start:word.char_end] == word.text  # offsets index the reply itself
        assert word.char_start >= previous_end and not word.text[0].isspace()
        previous_end = word.char_end


def test_duration_comes_from_the_wav_sample_count(espeak):
    clip = espeak.synthesize(REPLIES[0])
    with wave.open(str(clip.audio_path), "rb") as audio:
        assert audio.getnchannels() == 1 and audio.getsampwidth() == 2
        assert clip.duration_s == pytest.approx(audio.getnframes() / audio.getframerate())


def test_text_position_counts_characters_not_bytes(espeak):
    reply = "café naïve über test 😀 done"
    clip = espeak.synthesize(reply)
    assert [w.text for w in clip.words][:4] == ["café", "naïve", "über", "test"]
    assert clip.words[3].char_start == reply.index("test")  # 3 multi-byte characters before it
    assert clip.words[-1].char_start == reply.index("done")  # a 4-byte emoji before it


def test_last_word_of_a_long_reply_is_still_mapped(espeak):
    reply = _long_reply()
    clip = espeak.synthesize(reply)
    assert clip.words[-1].text == "FINALWORD." and clip.words[-1].char_start == reply.index("FINALWORD")


@pytest.mark.parametrize("text", ["", "   ", "\n\t"])
def test_empty_text_is_silent(espeak, text):
    clip = espeak.synthesize(text)
    assert clip.duration_s == 0.0 and clip.words == () and clip.audio_path is None


def test_unspoken_symbol_has_no_words_but_a_valid_clip(espeak):
    clip = espeak.synthesize("—")
    assert clip.words == () and clip.duration_s >= 0.0


def test_cache_returns_identical_clip(espeak, tmp_path):
    fresh = EspeakSynthesizer(audio_dir=str(tmp_path))
    first = fresh.synthesize(REPLIES[1])
    again = EspeakSynthesizer(audio_dir=str(tmp_path)).synthesize(REPLIES[1])  # served from disk
    assert again == first


def test_concurrent_synthesis_is_serialised_and_correct(tmp_path):
    synth = EspeakSynthesizer(audio_dir=str(tmp_path))
    texts = [f"Thread number {i} says hello over there." for i in range(8)]
    expected = {t: espeak_lib.render(t, "en-us", 165, 50).events for t in texts}
    results, errors = {}, []

    def work(text):
        try:
            results[text] = synth.word_events(text)
        except Exception as exc:  # pragma: no cover - reported below
            errors.append(exc)

    threads = [threading.Thread(target=work, args=(t,)) for t in texts]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors and set(results) == set(expected)
    for text, events in results.items():
        assert events == expected[text] and len(clean_events(text, events)) == 7  # every render is fresh


def test_voice_rate_pitch_are_applied_and_validated(tmp_path):
    slow = EspeakSynthesizer(rate=100, audio_dir=str(tmp_path)).synthesize(REPLIES[0])
    fast = EspeakSynthesizer(rate=300, audio_dir=str(tmp_path)).synthesize(REPLIES[0])
    assert slow.duration_s > 1.5 * fast.duration_s
    with pytest.raises(ValueError, match="espeak-ng --voices"):
        EspeakSynthesizer(voice="no-such-voice", audio_dir=str(tmp_path))
    with pytest.raises(ValueError, match="tts.rate"):
        EspeakSynthesizer(rate=20, audio_dir=str(tmp_path))
    with pytest.raises(ValueError, match="tts.pitch"):
        EspeakSynthesizer(pitch=200, audio_dir=str(tmp_path))


def test_missing_library_names_the_package():
    with pytest.raises(espeak_lib.EspeakUnavailable, match="espeak-ng"):
        espeak_lib._load("/nonexistent/libespeak-ng.so.1")
