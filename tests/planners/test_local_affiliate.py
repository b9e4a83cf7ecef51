"""A trigger's left edge moves onto the lexical affiliate (planners/local/affiliate.py); no model needed."""

import pytest

from emopose.planners.local.affiliate import affiliate, affiliate_region, affiliate_span


@pytest.mark.parametrize(("phrase", "cls", "expected"), [
    ("The fire exit is behind that grey door", "pointing", "behind that grey door"),
    ("your coat's on the hook", "pointing", "on the hook"),
    ("The gallery closes at five today", "neutral", "closes at five today"),
    ("The retake is on the 9th", "neutral", "on the 9th"),
    ("and the lift is out of order", "emphasizing", "out of order"),
    ("but I'm not sure about that", "doubting", "I'm not sure about that"),
    ("No, the gate stays shut", "rejecting", "the gate stays shut"),  # the refusal, not the no before it
    ("but no, I won't sign it", "rejecting", "I won't sign it"),
    ("Sorry, strollers stay downstairs", "rejecting", "strollers stay downstairs"),
    ("I'm afraid the roof is off limits", "rejecting", "the roof is off limits"),
    ("Oh, Mr. Lowe, please take a seat", "welcoming", "please take a seat"),  # interjection and name
    ("Aw, don't be glum", "comforting", "don't be glum"),
    ("I can see the delay is bothering you", "comforting", "the delay is bothering you"),
    ("Don't worry, your bag is safe here", "comforting", "your bag is safe here"),
    ("It's alright, plenty of people miss that step", "comforting", "plenty of people miss that step"),
    ("There's no hurry whatsoever", "comforting", "no hurry whatsoever"),
    ("Whatever happens, we'll be right here", "comforting", "we'll be right here"),
    ("Label every sample first; that's essential", "emphasizing", "that's essential"),  # the evaluating tag
])
def test_the_words_before_the_affiliate_are_trimmed(phrase, cls, expected):
    assert affiliate(phrase, cls) == expected


@pytest.mark.parametrize(("phrase", "cls"), [
    ("the crucial thing is to save", "emphasizing"),  # the evaluative subject is the emphasis itself
    ("No smoking on the balcony", "rejecting"),  # "No" is the prohibition itself, not a no before it
    ("No, never", "rejecting"),  # one word would remain
    ("The exit is here", "pointing"),  # one word would remain
    ("Yes, the tour is free", "agreeing"),
    ("Oh, hello there", "welcoming"),  # the interjection belongs to the greeting
    ("Ah, yes, that's correct", "agreeing"),  # an agreeing or doubting act keeps its interjection
    ("Hmm, I doubt it", "doubting"),
    ("I know it's been a long day", "comforting"),  # "I know" is kept (the module docstring says why)
    ("Don't worry, honestly", "comforting"),  # one word would remain
    ("Oh, Grace", "comforting"),
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


@pytest.mark.parametrize(("act", "cls", "region"), [
    ("Is the ferry running today? I wouldn't count on it.", "doubting", "I wouldn't count on it."),
    ("Whether the paint dries by noon, I can't tell you.", "doubting", "I can't tell you."),
    ("And how long the queue is, though, nobody knows.", "doubting", "nobody knows."),
    ("Are you sure that's the right bus?", "doubting", "Are you sure that's the right bus?"),  # no hedge
    ("I doubt it, honestly.", "doubting", "I doubt it, honestly."),
    ("Is it free? Yes, entry costs nothing.", "agreeing", "Is it free? Yes, entry costs nothing."),
])
def test_a_doubting_acts_stroke_goes_to_the_hedge_that_answers_its_question(act, cls, region):
    text = f"Good morning. {act}"
    start, end = affiliate_region(text, (text.index(act), len(text)), cls)
    assert text[start:end] == region and end == len(text)
