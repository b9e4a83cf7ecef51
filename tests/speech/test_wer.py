"""Word error rate (emopose/speech/wer.py): pure text, so it runs without the voice extra."""

from __future__ import annotations

import pytest

from emopose.speech.wer import wer, word_errors


def test_word_error_rate_counts_edits():
    assert word_errors("the cat sat on the mat", "the cat sat on mat") == (1, 6)
    assert word_errors("Isn't it well-known?", "isn't it well known") == (0, 4)
    assert wer("a b c", "x a b c y") == pytest.approx(2 / 3)


def test_an_empty_reference_scores_any_words_as_wrong():
    assert word_errors("", "hello") == (1, 0) and wer("", "hello") == 1.0 and wer("", "") == 0.0
