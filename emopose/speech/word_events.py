"""Engine word events -> WordTiming spans of the reply (character offsets and onsets).

espeak reports one event per *spoken* word at the character where that word's source text starts, so
a written token can carry several events ("3.5" -> three, point, five; "$20" -> dollar-sign, twenty;
an emoji -> its name's words) and a few events are strays: on whitespace (emoji names, clause ends) or
pointing back to an earlier clause. The mapping therefore:
  1. keeps events that move forward through the text and land on a non-space character;
  2. cuts each whitespace-separated token at its kept event positions (the first piece starts at the
     token start, so leading quotes or brackets belong to the first word);
  3. gives each piece the earliest onset of its events, made monotone and clamped into [0, T_a].
Tokens with no event (a lone dash, an unspoken symbol) get no WordTiming, so
SpeechClip.onset_at_char(i) for a character there returns the next spoken word's onset.
"""

from __future__ import annotations

import bisect
import re
from collections.abc import Iterable

from emopose.speech.clip import WordTiming
from emopose.speech.espeak_lib import WordEvent

_TOKEN = re.compile(r"\S+")


def clean_events(text: str, events: Iterable[WordEvent]) -> dict[int, float]:
    """Character index -> earliest onset, for the events that move forward and land on a character."""
    kept: dict[int, float] = {}
    last = -1
    for event in events:
        index = event.char_index
        if not 0 <= index < len(text) or index < last or text[index].isspace():
            continue
        last = index
        kept.setdefault(index, event.audio_s)
    return kept


def words_from_events(text: str, events: Iterable[WordEvent], duration_s: float) -> tuple[WordTiming, ...]:
    kept = clean_events(text, events)
    positions = sorted(kept)
    words: list[WordTiming] = []
    previous = 0.0
    for token in _TOKEN.finditer(text):
        lo = bisect.bisect_left(positions, token.start())
        hi = bisect.bisect_left(positions, token.end())
        inside = positions[lo:hi]
        if not inside:
            continue
        cuts = [token.start(), *inside[1:], token.end()]
        onsets = [min(kept[i] for i in inside), *(kept[i] for i in inside[1:])]
        for start, end, onset in zip(cuts[:-1], cuts[1:], onsets):
            previous = min(max(onset, previous, 0.0), duration_s)
            words.append(WordTiming(text[start:end], start, end, previous))
    return tuple(words)


def onset_of_span(text: str, events: Iterable[WordEvent], start: int, end: int) -> float | None:
    """The engine's onset for the phrase text[start:end]: its first word event inside the span, else the
    word event that covers `start` from earlier in the same token (espeak gives "well-known" one event)."""
    kept = clean_events(text, events)
    inside = [i for i in kept if start <= i < end]
    if inside:
        return kept[min(inside)]
    token_start = start
    while token_start > 0 and not text[token_start - 1].isspace():
        token_start -= 1
    covering = [i for i in kept if token_start <= i < start]
    return kept[max(covering)] if covering else None
