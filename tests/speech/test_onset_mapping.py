"""Engine word events -> reply characters: onset_at_char lands on the right spoken word."""

from __future__ import annotations

import pytest

from emopose.speech.espeak_lib import WordEvent
from emopose.speech.word_events import clean_events, onset_of_span, words_from_events


def _event_at(events, index):
    return min(e.audio_s for e in events if e.char_index == index)


@pytest.mark.parametrize("reply, trigger", [
    ("It weighs 3.5 kg and costs $20, 50% off.", "kg"),
    ("It weighs 3.5 kg and costs $20, 50% off.", "$20"),
    ("It weighs 3.5 kg and costs $20, 50% off.", "50% off"),
    ("It weighs 3.5 kg and costs $20, 50% off.", "off"),
    ("The price is $1,250.75 — about €30; look over there.", "over there"),
    ("😀 great news 🎉 yes, welcome!", "great news"),
    ("😀 great news 🎉 yes, welcome!", "yes"),
    ("Hi 👋🏽 there, café ☕ is open.", "café"),
    ("We meet on 2024-05-01 at 10:30 a.m., right here.", "right here"),
    ('"Welcome!" she said — the arm (over there)... Really?', "over there"),
])
def test_trigger_onset_is_the_engine_event_of_its_first_word(espeak, reply, trigger):
    clip = espeak.synthesize(reply)
    events = espeak.word_events(reply)
    pos = reply.index(trigger)
    assert clip.onset_at_char(pos) == pytest.approx(_event_at(events, pos))
    assert onset_of_span(reply, events, pos, pos + len(trigger)) == pytest.approx(_event_at(events, pos))


def test_numbers_split_into_several_spoken_words_keep_order(espeak):
    reply = "This sample weighs 3.5 kg, twice the limit."
    clip = espeak.synthesize(reply)
    three, kg, twice = (clip.onset_at_char(reply.index(s)) for s in ("3.5", "kg", "twice"))
    assert three < kg < twice
    pieces = [w.text for w in clip.words if reply.index("3.5") <= w.char_start < reply.index("3.5") + 3]
    assert "".join(pieces) == "3.5" and len(pieces) >= 2  # "three" / "point five"


def test_a_character_in_whitespace_or_an_unspoken_token_maps_to_the_next_word(espeak):
    reply = "Stop — over there."
    clip = espeak.synthesize(reply)
    assert clip.onset_at_char(reply.index("—")) == clip.onset_at_char(reply.index("over"))
    assert clip.onset_at_char(reply.index(" over")) == clip.onset_at_char(reply.index("over"))


# -- the mapping rules on synthetic events (no engine) --------------------------------------------
def test_stray_events_on_whitespace_or_backwards_are_dropped():
    text = "Look there. And here"
    events = [WordEvent(0, 4, 0.0), WordEvent(5, 5, 0.3), WordEvent(11, 0, 0.9),  # whitespace stray
              WordEvent(12, 3, 1.0), WordEvent(6, 0, 1.1),  # points back into "there": dropped
              WordEvent(16, 4, 1.2), WordEvent(-1, 0, 1.3), WordEvent(99, 1, 1.3)]
    assert clean_events(text, events) == {0: 0.0, 5: 0.3, 12: 1.0, 16: 1.2}
    words = words_from_events(text, events, 1.5)
    assert [(w.text, w.start_s) for w in words] == [("Look", 0.0), ("there.", 0.3), ("And", 1.0),
                                                    ("here", 1.2)]


def test_token_pieces_start_at_the_token_and_onsets_are_clamped():
    text = '("$20")'
    events = [WordEvent(2, 1, 0.5), WordEvent(3, 2, 0.2), WordEvent(3, 2, 0.4)]
    words = words_from_events(text, events, 0.45)
    assert [(w.text, w.char_start) for w in words] == [('("$', 0), ('20")', 3)]
    # a token starts at its earliest sound ("$20" is spoken "twenty dollars"); order is kept
    assert [w.start_s for w in words] == [0.2, 0.2]
    assert [w.start_s for w in words_from_events(text, events, 0.1)] == [0.1, 0.1]  # clamped into T_a


def test_a_word_without_its_own_event_uses_the_covering_event():
    text = "a well-known fact"
    events = [WordEvent(0, 1, 0.0), WordEvent(2, 4, 0.2), WordEvent(13, 4, 0.7)]
    assert onset_of_span(text, events, text.index("known"), text.index("known") + 5) == 0.2
    assert onset_of_span(text, events, text.index("fact"), len(text)) == 0.7
