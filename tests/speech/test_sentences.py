"""The incremental sentence splitter: the same sentences however the text is chunked."""

import pytest

from emopose.speech.sentences import SentenceSplitter

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
