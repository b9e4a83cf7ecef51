"""A trigger's left edge moves onto the lexical affiliate (planners/local/affiliate.py); no model needed."""

import pytest

from emopose.planners.local.affiliate import affiliate, affiliate_span


@pytest.mark.parametrize(("phrase", "cls", "expected"), [
    ("The fire exit is behind that grey door", "pointing", "behind that grey door"),
    ("your coat's on the hook", "pointing", "on the hook"),
    ("The gallery closes at five today", "neutral", "closes at five today"),
    ("The retake is on the 9th", "neutral", "on the 9th"),
    ("and the lift is out of order", "emphasizing", "out of order"),
    ("but I'm not sure about that", "doubting", "I'm not sure about that"),
])
def test_the_words_before_the_affiliate_are_trimmed(phrase, cls, expected):
    assert affiliate(phrase, cls) == expected


@pytest.mark.parametrize(("phrase", "cls"), [
    ("the crucial thing is to save", "emphasizing"),  # the evaluative subject is the emphasis itself
    ("No, we're not changing the menu", "rejecting"),  # the no is the affiliate (contract.TRIGGER_RULE)
    ("The exit is here", "pointing"),  # one word would remain
    ("Yes, the tour is free", "agreeing"),
    ("and", "pointing"),  # nothing would remain
])
def test_an_affiliate_it_is_unsure_of_stays_whole(phrase, cls):
    assert affiliate(phrase, cls) == phrase


def test_the_moved_start_is_where_the_schedule_finds_the_shorter_trigger():
    text = "The coffee is on the left. The exit is on the left too."
    second = text.index("The exit")
    span = (second, len(text) - len(" too."))
    # "on the left" occurs first in the earlier sentence: the schedule would aim there, so it stays whole
    assert affiliate_span(text, span, "pointing") == span
    text = "Good morning! The cloakroom is downstairs on the left."
    start = text.index("The")
    assert text[slice(*affiliate_span(text, (start, len(text) - 1), "pointing"))] == "downstairs on the left"


def test_an_empty_or_one_word_trigger_is_kept_as_it_is():
    text = "Welcome!"
    assert affiliate_span(text, (0, 0), "welcoming") == (0, 0)
    assert affiliate_span(text, (0, 7), "welcoming") == (0, 7)
    assert affiliate("", "pointing") == ""
