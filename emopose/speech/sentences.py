"""Cut a reply into sentences while it streams in: feed(text) -> the sentences it completed.

A sentence ends at `.`, `!`, `?` or `...` (closing quotes and brackets stay with it) followed by
whitespace; the whitespace must have arrived, so "3." waits to see whether "3.5" follows. A period
does not end a sentence after a known abbreviation ("Dr.", "e.g."), a single capital initial ("J.")
or between digits ("3.5"). A line break ends one too (a list item is said as a sentence).
flush() returns whatever is left when the stream ends.
"""

from __future__ import annotations

import re

ABBREVIATIONS = frozenset({
    "mr", "mrs", "ms", "dr", "prof", "sr", "jr", "st", "mt", "vs", "etc", "e.g", "i.e", "approx", "no",
    "fig", "inc", "ltd", "co", "dept", "min", "max", "ca", "cf", "al", "jan", "feb", "mar", "apr",
    "jun", "jul", "aug", "sep", "sept", "oct", "nov", "dec", "a.m", "p.m", "u.s",
})
_END = re.compile(r"(?:\.\.\.|…|[.!?])+[\"')\]]*(?=\s)|\n")
_WORD_BEFORE = re.compile(r"([\w.]+)$")


class SentenceSplitter:
    def __init__(self) -> None:
        self._buffer = ""

    def feed(self, text: str) -> list[str]:
        """Add streamed text; the sentences now complete, stripped and whitespace-normalised, in order."""
        self._buffer += text
        out, start = [], 0
        for match in _END.finditer(self._buffer):
            if match.group() != "\n" and not self._ends_sentence(self._buffer[start:match.start()], match.group()):
                continue
            sentence = " ".join(self._buffer[start:match.end()].split())
            if sentence:
                out.append(sentence)
            start = match.end()
        self._buffer = self._buffer[start:]
        return out

    def flush(self) -> str:
        """The unfinished rest (the model stopped mid-sentence, or without a final stop)."""
        rest, self._buffer = " ".join(self._buffer.split()), ""
        return rest

    @staticmethod
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
