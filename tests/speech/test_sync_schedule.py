"""Schedule modes against the engine's true onsets: words mode is closer than the anchor equation."""

from __future__ import annotations

import logging
from types import SimpleNamespace

import pytest

from emopose.speech.word_events import onset_of_span
from emopose.stages.schedule import ScheduleStage, anchor_release_times, word_release_times

CRAFTED = [  # replies where characters and speaking time disagree: numbers, symbols, pauses
    ("It costs $1,250.75, about 30% more; yes, that is right.", ["yes"]),
    ("The 2024-05-01 release weighs 3.5 kg. Look over there!", ["Look over there"]),
    ("Welcome!!! 😀😀 The demo, at 10:30 a.m., is right here.", ["Welcome", "right here"]),
    ("No. Absolutely not — put it down, please.", ["No", "put it down"]),
    ("Hmm... I'm not sure. Maybe 50/50? The exit is on your left.", ["not sure", "on your left"]),
]


@pytest.mark.parametrize("reply, triggers", CRAFTED)
def test_words_mode_is_closer_to_the_true_onset_than_anchor(espeak, reply, triggers):
    clip = espeak.synthesize(reply)
    events = espeak.word_events(reply)
    truth = [onset_of_span(reply, events, reply.index(t), reply.index(t) + len(t)) for t in triggers]
    anchor = [t for t, _ in anchor_release_times(reply, triggers, clip.duration_s)]
    words = [t for t, how in word_release_times(reply, triggers, clip)]
    for true, a, w in zip(truth, anchor, words):
        assert abs(w - true) <= 0.06
        assert abs(w - true) <= abs(a - true)
    assert sum(abs(a - t) for a, t in zip(anchor, truth)) > 0.1  # the equation really is off here


def _turn(reply, triggers):
    records = [SimpleNamespace(resolved=SimpleNamespace(record=SimpleNamespace(trigger=t))) for t in triggers]
    return SimpleNamespace(plan=SimpleNamespace(reply=reply), modulated=records)


@pytest.mark.parametrize("mode", ["anchor", "words"])
def test_missing_triggers_are_flagged_and_logged(espeak, library, mode, caplog):
    reply = "Welcome to the lab. The robot arm is over there."
    with caplog.at_level(logging.WARNING, logger="emopose.stages.schedule"):
        speech, schedule = ScheduleStage(espeak, library.limits, mode=mode)(
            _turn(reply, ["Welcome", "under the table", "over there"]))
    assert speech.text == reply and speech.words
    assert schedule.missing_triggers == [1]
    assert [r.how for r in schedule.releases][1] == "interpolated"
    assert "under the table" in caplog.text and "say-do" in caplog.text
    assert schedule.releases[0].release_s < schedule.releases[1].release_s < schedule.releases[2].release_s
