"""One sentence rule (emopose/sentences.py): streamed, whole, and around a character."""

import pytest

from emopose.sentences import SentenceSplitter, sentence_span, split_sentences

TEXT = ("Dr. Smith is in room 3.5 today! Is that far?  No, it is about 2.5 km away, e.g. past the J. Lee "
        "hall... Follow the signs.\nThen turn left")
SENTENCES = ["Dr. Smith is in room 3.5 today!", "Is that far?",
             "No, it is about 2.5 km away, e.g. past the J. Lee hall...", "Follow the signs."]


@pytest.mark.parametrize("size", [1, 2, 3, 7, len(TEXT)])
def test_sentences_come_out_whole_whatever_the_chunking(size):
    splitter, out = SentenceSplitter(), []
    for k in range(0, len(TEXT), size):
        out += splitter.feed(TEXT[k:k + size])
    assert out == SENTENCES
    assert splitter.flush() == "Then turn left" and splitter.flush() == ""


def test_a_stop_waits_for_the_next_character():
    splitter = SentenceSplitter()
    assert splitter.feed("It costs 3.") == []  # "3.5" may follow
    assert splitter.feed("5 euros. ") == ["It costs 3.5 euros."]
    assert splitter.feed('He said "go!" ') == ['He said "go!"']


def test_the_whole_text_splits_as_the_stream_does():
    assert split_sentences(TEXT) == [*SENTENCES, "Then turn left"]
    assert split_sentences("  ") == [] and split_sentences("No stop") == ["No stop"]


def test_a_character_belongs_to_its_sentence_and_a_gap_to_the_one_before():
    text = 'Look at the board. "It is new!"  Dr. Lee made it'
    board, new, lee = text.index("board"), text.index("new"), text.index("Lee")
    assert text[slice(*sentence_span(text, board))] == "Look at the board."
    assert text[slice(*sentence_span(text, new))] == '"It is new!"'
    assert text[slice(*sentence_span(text, text.index("  ") + 1))] == '"It is new!"'
    assert text[slice(*sentence_span(text, lee))] == "Dr. Lee made it"
