"""Piper's phoneme alignments -> the reply's word onsets.

Piper phonemizes a reply with espeak into one phoneme list per sentence, and the aligned model says how
many audio samples each phoneme takes. The phoneme stream has no link back to the text, and espeak
merges short words ("on the" -> one group "ɔnðə") or expands one token into several ("3.5" -> three
point five), so counting space-separated groups goes wrong. Instead every whitespace token is
phonemized on its own, the concatenation of those is aligned with the sentence stream character by
character (difflib), and a token's onset is the start of the stream phoneme its first phoneme matched,
moved back to the start of its group when no earlier token sits in that group (so a word's onset is
where its sound starts, not where the first *matching* phoneme is). Onsets are monotone; a token with
no phonemes or no match (a lone dash) gets no WordTiming, as with espeak.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from difflib import SequenceMatcher

_TOKEN = re.compile(r"\S+")
NOT_SOUNDS = frozenset(" .,;:!?\"'()[]-—–…")  # group breaks and punctuation: no audio of a word


@dataclass(frozen=True)
class TokenPlace:
    """A text token [char_start, char_end) and where its sound starts: sentence, phoneme index."""

    char_start: int
    char_end: int
    sentence: int
    phoneme: int


def place_tokens(text: str, sentences: Sequence[Sequence[str]],
                 phonemize_token: Callable[[str], str]) -> list[TokenPlace]:
    """Each spoken token of `text` placed on the sentences' phoneme lists (see the module docstring)."""
    stream: list[tuple[int, int]] = []  # (sentence, phoneme index) of every sounding phoneme
    for k, phonemes in enumerate(sentences):
        stream += [(k, j) for j, p in enumerate(phonemes) if p not in NOT_SOUNDS]
    stream_text = "".join(sentences[k][j] for k, j in stream)
    tokens, token_text = [], []
    offset = 0
    for match in _TOKEN.finditer(text):
        sounds = "".join(p for p in phonemize_token(match.group()) if p not in NOT_SOUNDS)
        tokens.append((match.start(), match.end(), offset, offset + len(sounds)))
        token_text.append(sounds)
        offset += len(sounds)
    to_stream = _matched_positions("".join(token_text), stream_text)
    places: list[TokenPlace] = []
    previous = -1
    for char_start, char_end, lo, hi in tokens:
        first = next((i for i in range(lo, hi) if i in to_stream), None)
        if first is None:
            continue
        position = min(max(to_stream[first] - (first - lo), previous + 1, 0), len(stream) - 1)
        if position <= previous:
            continue  # the stream is used up: the token was not spoken
        sentence, phoneme = stream[position]
        group_start = _group_start(sentences[sentence], phoneme)
        earliest = stream.index((sentence, group_start)) if group_start != phoneme else position
        if earliest > previous:
            position, phoneme = earliest, group_start
        places.append(TokenPlace(char_start, char_end, sentence, phoneme))
        previous = position
    return places


def phoneme_starts_s(num_samples: Sequence[int], sample_rate: int) -> list[float]:
    """Start time of each phoneme of a sentence from its alignments [BOS, phonemes..., EOS]."""
    starts, total = [], int(num_samples[0]) if num_samples else 0
    for count in num_samples[1:-1]:
        starts.append(total / sample_rate)
        total += int(count)
    return starts


def _matched_positions(tokens: str, stream: str) -> dict[int, int]:
    matcher = SequenceMatcher(None, tokens, stream, autojunk=False)
    return {block.a + i: block.b + i for block in matcher.get_matching_blocks() for i in range(block.size)}


def _group_start(phonemes: Sequence[str], index: int) -> int:
    """The first sounding phoneme of the space-separated group that holds phonemes[index]."""
    start = index
    while start > 0 and phonemes[start - 1] != " ":
        start -= 1
    while start < index and phonemes[start] in NOT_SOUNDS:
        start += 1
    return start
