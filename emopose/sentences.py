"""Where a sentence ends: one rule for every caller that cuts text into sentences.

A sentence ends at `.`, `!`, `?` or `...` (closing quotes and brackets stay with it) followed by
whitespace; the whitespace must have arrived, so "3." waits to see whether "3.5" follows. A period
does not end a sentence after a known abbreviation ("Dr.", "e.g."), a single capital initial ("J.")
or between digits ("3.5"). A line break ends one too (a list item is said as a sentence).
Users: a streamed reply cut as it arrives (SentenceSplitter), the tour's lines packed into plannable
pieces and resumed from the sentence a question cut into (emopose/tour/voice.py), and the sentence
around a pointing record's trigger (emopose/scene/view.py). In the base layer, so the scene can use it.
"""

from __future__ import annotations

import re
from itertools import pairwise

ABBREVIATIONS = frozenset({
    "mr", "mrs", "ms", "dr", "prof", "sr", "jr", "st", "mt", "vs", "etc", "e.g", "i.e", "approx", "no",
    "fig", "inc", "ltd", "co", "dept", "min", "max", "ca", "cf", "al", "jan", "feb", "mar", "apr",
    "jun", "jul", "aug", "sep", "sept", "oct", "nov", "dec", "a.m", "p.m", "u.s",
})
_END = re.compile(r"(?:\.\.\.|…|[.!?])+[\"')\]]*(?=\s)|\n")
_WORD_BEFORE = re.compile(r"([\w.]+)$")
_SPACE = re.compile(r"\s*")


def sentence_bounds(text: str) -> list[tuple[int, int]]:
    """(end, next_start) of every sentence the text completes, in order: `end` is just after its last
    mark, `next_start` after the whitespace that follows. The text after the last one is unfinished."""
    bounds, start = [], 0
    for match in _END.finditer(text):
        if match.group() != "\n" and not _ends_sentence(text[start:match.start()], match.group()):
            continue
        bounds.append((match.end(), _SPACE.match(text, match.end()).end()))
        start = match.end()
    return bounds


def split_sentences(text: str) -> list[str]:
    """The text's sentences, stripped, the unfinished rest last (empty ones left out)."""
    cuts = [0, *(end for end, _ in sentence_bounds(text)), len(text)]
    return [piece for a, b in pairwise(cuts) if (piece := text[a:b].strip())]


def sentence_span(text: str, pos: int) -> tuple[int, int]:
    """(start, end) of the sentence that character `pos` belongs to; whitespace between two sentences
    belongs to the one before."""
    start = 0
    for end, next_start in sentence_bounds(text):
        if next_start > pos:
            return start, end
        start = next_start
    return start, len(text)


class SentenceSplitter:
    """Cut a reply into sentences while it streams in: feed(text) -> the sentences it completed."""

    def __init__(self) -> None:
        self._buffer = ""

    def feed(self, text: str) -> list[str]:
        """Add streamed text; the sentences now complete, stripped and whitespace-normalised, in order."""
        self._buffer += text
        bounds = sentence_bounds(self._buffer)
        cuts = [0, *(end for end, _ in bounds)]
        out = [sentence for a, b in pairwise(cuts) if (sentence := " ".join(self._buffer[a:b].split()))]
        self._buffer = self._buffer[cuts[-1]:]
        return out

    def flush(self) -> str:
        """The unfinished rest (the model stopped mid-sentence, or without a final stop)."""
        rest, self._buffer = " ".join(self._buffer.split()), ""
        return rest


def _ends_sentence(before: str, mark: str) -> bool:
    if not mark.startswith(".") or mark.startswith("..."):
        return True  # ! ? and ellipses always end one
    word = _WORD_BEFORE.search(before)
    if word is None:
        return True
    token = word.group(1)
    if token.lower().rstrip(".") in ABBREVIATIONS:
        return False
    return not (len(token) == 1 and token.isupper())  # an initial: "J. Smith"
