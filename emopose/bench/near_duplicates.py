"""Near-duplicate detection for the leakage rule (spec, "Leakage rule").

Normalise text (lowercase, strip punctuation, collapse whitespace). Two texts are near-duplicates if
their normalised forms are equal, or the Jaccard similarity of their word 3-gram sets is >= 0.5, or
the 3-grams of one text with >= 4 words are >= 0.7 contained in the other's. An inverted index from
3-gram to texts keeps the check near-linear: only texts sharing a 3-gram are ever compared.
"""

from __future__ import annotations

import re
from collections import Counter, defaultdict
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

JACCARD_LIMIT = 0.5
CONTAINMENT_LIMIT = 0.7
CONTAINMENT_MIN_WORDS = 4
_PUNCTUATION = re.compile(r"[^\w\s]")


def normalise(text: str) -> str:
    text = _PUNCTUATION.sub(" ", text.lower().replace("\u2019", "'").replace("'", ""))
    return " ".join(text.split())


def word_trigrams(normalised: str) -> frozenset[tuple[str, ...]]:
    words = normalised.split()
    return frozenset(tuple(words[i:i + 3]) for i in range(len(words) - 2))


@dataclass(frozen=True)
class Text:
    key: str  # e.g. "bench:bench-easy-pointing-01"
    raw: str
    normalised: str
    grams: frozenset[tuple[str, ...]]

    @classmethod
    def of(cls, key: str, raw: str) -> Text:
        norm = normalise(raw)
        return cls(key, raw, norm, word_trigrams(norm))

    @property
    def words(self) -> int:
        return len(self.normalised.split())


@dataclass(frozen=True)
class NearDuplicate:
    a: Text
    b: Text
    reason: str

    def __str__(self) -> str:
        return f"{self.a.key} ~ {self.b.key} ({self.reason}): {self.a.raw!r} / {self.b.raw!r}"


def verdict(a: Text, b: Text, shared: int | None = None) -> str | None:
    """Why a and b are near-duplicates, or None. `shared` (common 3-grams) may be passed in if known."""
    if a.normalised == b.normalised:
        return "equal after normalisation"
    if shared is None:
        shared = len(a.grams & b.grams)
    if not shared:
        return None
    jaccard = shared / len(a.grams | b.grams)
    if jaccard >= JACCARD_LIMIT:
        return f"3-gram Jaccard {jaccard:.2f}"
    for x in (a, b):
        if x.words >= CONTAINMENT_MIN_WORDS and shared / len(x.grams) >= CONTAINMENT_LIMIT:
            return f"{shared / len(x.grams):.2f} of {x.key}'s 3-grams contained"
    return None


class TrigramIndex:
    """Inverted index over word 3-grams (and normalised text, for equality) of a set of texts."""

    def __init__(self, texts: Iterable[Text]) -> None:
        self.texts: list[Text] = list(texts)
        self.postings: dict[tuple[str, ...], list[int]] = defaultdict(list)
        self.by_normalised: dict[str, list[int]] = defaultdict(list)
        for k, text in enumerate(self.texts):
            for gram in text.grams:
                self.postings[gram].append(k)
            self.by_normalised[text.normalised].append(k)

    def candidates(self, query: Text) -> Counter:
        """{index: shared 3-gram count} for every indexed text sharing a 3-gram or the normalised text."""
        shared: Counter = Counter()
        for gram in query.grams:
            shared.update(self.postings.get(gram, ()))
        for k in self.by_normalised.get(query.normalised, ()):
            shared.setdefault(k, 0)
        return shared

    def matches(self, query: Text) -> list[NearDuplicate]:
        found = []
        for k, shared in self.candidates(query).items():
            other = self.texts[k]
            reason = verdict(query, other, shared)
            if reason and other.key != query.key:
                found.append(NearDuplicate(query, other, reason))
        return found


def cross_duplicates(queries: Sequence[Text], reference: Sequence[Text]) -> list[NearDuplicate]:
    """Every (query, reference) near-duplicate pair."""
    index = TrigramIndex(reference)
    return [d for q in queries for d in index.matches(q)]


def internal_duplicates(texts: Sequence[Text]) -> list[NearDuplicate]:
    """Every near-duplicate pair within one collection, each pair once."""
    index = TrigramIndex(texts)
    position = {t.key: k for k, t in enumerate(texts)}
    return [d for k, t in enumerate(texts) for d in index.matches(t) if position[d.b.key] > k]
