"""Split an utterance into candidate communicative segments, keeping character spans.

Boundaries come in two strengths: strong after sentence punctuation (. ! ? ; : and dashes) and weak at
commas and clause-joining conjunctions ("and", "but", "so", "then", "because", "while"). The local
planner decides which candidate boundaries separate different communicative acts.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

_STRONG = re.compile(r"(?<=[.!?;:])[\"')\]]*\s+|\s+[-\u2013\u2014]+\s+")
_WEAK = re.compile(r",\s+|\s+(?=(?:and|but|so|then|because|while|although|though)\s)", re.IGNORECASE)
_WORD = re.compile(r"[\w']+")


@dataclass(frozen=True)
class Segment:
    text: str
    start: int
    end: int
    strong_break_before: bool

    @property
    def words(self) -> int:
        return len(_WORD.findall(self.text))


def _split(text: str, start: int, pattern: re.Pattern[str]) -> list[tuple[int, int]]:
    spans, cursor = [], start
    for match in pattern.finditer(text, start - start):
        spans.append((cursor, start + match.start()))
        cursor = start + match.end()
    spans.append((cursor, start + len(text)))
    return [(a, b) for a, b in spans if b > a]


def segments(utterance: str) -> list[Segment]:
    """Candidate segments in order; each has at least one word character."""
    out: list[Segment] = []
    for s_start, s_end in _split(utterance, 0, _STRONG):
        sentence = utterance[s_start:s_end]
        for k, (a, b) in enumerate(_split(sentence, s_start, _WEAK)):
            piece = utterance[a:b]
            stripped = piece.strip(" \t\n,;:")
            if not _WORD.search(stripped):
                continue
            offset = piece.find(stripped)
            out.append(Segment(stripped, a + offset, a + offset + len(stripped), k == 0))
    return out
