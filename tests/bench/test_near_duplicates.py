"""The near-duplicate rule of the leakage test, on hand-made pairs."""

from emopose.bench.near_duplicates import (
    Text,
    cross_duplicates,
    internal_duplicates,
    normalise,
    verdict,
    word_trigrams,
)


def t(key, raw):
    return Text.of(key, raw)


def test_normalise_and_trigrams():
    assert normalise("  Don't   touch THAT -- please!") == "dont touch that please"
    assert word_trigrams("a b c d") == {("a", "b", "c"), ("b", "c", "d")}
    assert word_trigrams("a b") == frozenset()


def test_equal_after_normalisation():
    assert verdict(t("a", "Yes!"), t("b", "yes")) == "equal after normalisation"
    assert verdict(t("a", "Yes."), t("b", "No.")) is None


def test_jaccard_threshold():
    # 5 words -> 3 trigrams each; sharing 2 of 4 distinct -> Jaccard 0.5, the boundary: a duplicate
    a, b = t("a", "please look at the door"), t("b", "please look at the window")
    assert verdict(a, b) == "3-gram Jaccard 0.50"
    # sharing 1 of 5 distinct (0.2), containment 1/3 for both: not a duplicate
    a, b = t("a", "please look at the door"), t("b", "now look at the window")
    assert verdict(a, b) is None


def test_containment_needs_four_words():
    short = t("a", "the red door")             # 3 words: containment does not apply
    long_ = t("b", "walk through the red door and turn left at the big sign")
    assert verdict(short, long_) is None
    contained = t("c", "turn left at the big sign")  # 6 words, all 4 trigrams inside long_
    assert "contained" in verdict(contained, long_)


def test_index_finds_pairs_once():
    texts = [t("s:1", "Welcome to the lab, come on in."), t("s:2", "welcome to the lab come on in"),
             t("s:3", "The meeting starts at three."), t("s:4", "Something else entirely here.")]
    pairs = internal_duplicates(texts)
    assert [(p.a.key, p.b.key) for p in pairs] == [("s:1", "s:2")]
    cross = cross_duplicates([texts[2]], [t("train:9", "the meeting starts at three sharp today")])
    assert len(cross) == 1 and cross[0].b.key == "train:9"
