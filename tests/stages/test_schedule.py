import pytest

from emopose.speech.clip import SpeechClip, WordTiming
from emopose.stages.schedule import anchor_release_times, word_release_times


def test_paper_equation_hand_computed():
    reply = "Hello there, look at the screen."  # 32 chars
    times = anchor_release_times(reply, ["Hello", "screen"], 3.2)
    assert times[0] == (pytest.approx((0 + 2.5) / 32 * 3.2), "anchor")
    assert times[1] == (pytest.approx((25 + 3) / 32 * 3.2), "anchor")


def test_first_occurrence_and_case_insensitive():
    times = anchor_release_times("no, No, NO", ["NO"], 1.0)
    assert times[0][0] == pytest.approx(1 / 10)


def test_missing_anchor_interpolated_between_neighbours():
    times = anchor_release_times("a b c d e f g h i j", ["a", "zzz", "j"], 2.0)
    t0, t2 = times[0][0], times[2][0]
    assert times[1] == (pytest.approx((t0 + t2) / 2), "interpolated")


def test_missing_at_edges_uses_zero_and_duration():
    times = anchor_release_times("x" * 10, ["missing", "xxxxxxxxxx", "gone"], 4.0)
    assert times[0][0] == pytest.approx(times[1][0] / 2)
    assert times[2][0] == pytest.approx((times[1][0] + 4.0) / 2)


def test_no_match_even_spacing_and_single_immediate():
    assert anchor_release_times("abc", [None, "q", "r", "s"], 4.0) == [(0.5, "even"), (1.5, "even"),
                                                                    (2.5, "even"), (3.5, "even")]
    assert anchor_release_times("abc", ["zzz"], 4.0) == [(0.0, "immediate")]


def test_words_mode_uses_true_onsets_with_anchor_fallback():
    reply = "Welcome in. The door is there."
    clip = SpeechClip(reply, 2.0, (WordTiming("Welcome", 0, 7, 0.05), WordTiming("in", 8, 10, 0.4),
                                  WordTiming("The", 12, 15, 0.8), WordTiming("door", 16, 20, 1.0),
                                  WordTiming("is", 21, 23, 1.3), WordTiming("there", 24, 29, 1.5)))
    times = word_release_times(reply, ["Welcome", "there", "absent"], clip)
    assert times[0] == (0.05, "words") and times[1] == (1.5, "words")
    assert times[2][1] == "interpolated"
