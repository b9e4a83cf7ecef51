"""A text's espeak render does not depend on what was rendered before, and a cached clip's word onsets
are those of the WAV it plays."""

from __future__ import annotations

import json
import pickle
import subprocess
import sys

from emopose.speech import espeak_lib
from emopose.speech.espeak import EspeakSynthesizer
from emopose.speech.wav import read_pcm, write_wav
from emopose.speech.word_events import words_from_events

TEXT = "Welcome to the lab! The robot arm is over there."
OTHERS = ["Hello? Yes, I am here... really!", "It weighs 3.5 kg and costs $20, 50% off.",
          "Well, that is a long story; let me tell you, slowly.", "日本語 テキスト and then English words."]


def _render_in_a_new_process(text: str) -> espeak_lib.Rendering:
    """The first render of a process that never rendered anything: the reference a fresh state gives."""
    code = ("import pickle, sys; from emopose.speech.espeak_lib import _Engine; "
            f"sys.stdout.buffer.write(pickle.dumps(_Engine(None).render({text!r}, 'en-us', 165, 50)))")
    return pickle.loads(subprocess.run([sys.executable, "-c", code], capture_output=True, check=True).stdout)


def test_the_same_text_renders_identically_whatever_was_rendered_before():
    fresh = _render_in_a_new_process(TEXT)
    renders = []
    for other in OTHERS:
        espeak_lib.render(other)
        renders.append(espeak_lib.render(TEXT))
    renders.append(espeak_lib.render(TEXT))  # straight after itself
    for rendering in renders:
        assert rendering.pcm == fresh.pcm
        assert rendering.events == fresh.events


def test_a_clip_after_other_clips_has_the_fresh_clips_audio_and_onsets(tmp_path):
    fresh = _render_in_a_new_process(TEXT)
    synth = EspeakSynthesizer(audio_dir=str(tmp_path))
    for other in OTHERS:
        synth.synthesize(other)
    clip = synth.synthesize(TEXT)
    assert clip.words == words_from_events(TEXT, fresh.events, fresh.duration_s)
    assert read_pcm(clip.audio_path) == fresh.pcm  # the audio played is the audio the onsets come from


def test_a_cache_entry_whose_wav_is_other_audio_is_rendered_again(tmp_path):
    first = EspeakSynthesizer(audio_dir=str(tmp_path)).synthesize(TEXT)
    other = espeak_lib.render(OTHERS[0])
    write_wav(first.audio_path, other.pcm, other.sample_rate)  # the WAV no longer matches its events
    again = EspeakSynthesizer(audio_dir=str(tmp_path)).synthesize(TEXT)
    assert again == first and read_pcm(again.audio_path) == espeak_lib.render(TEXT).pcm
    meta = json.loads(first.audio_path.with_suffix(".json").read_text())
    assert meta["events"] == [[e.char_index, e.length, e.audio_s] for e in espeak_lib.render(TEXT).events]
