"""How long a chat model's spoken reply may run (planner=annotate): at most `max_sentences` sentences and
`max_speech_s` seconds of speech, estimated at the speech layer's speaking rate (EstimatedSpeech, the
tts=none estimate). The prompt states the bound (prompts/annotate.md); here it is enforced, because a
small model ignores it (18 sentences, a minute of speech, were seen): the reply ends at the last
sentence boundary within the bound. The first sentence is always kept. A whole reply (unstreamed) also
stays within the contract's MAX_REPLY_CHARS, so the parse stage never cuts it mid-word; a streamed
reply is performed sentence by sentence, each its own turn, so there the bound closes the stream.
"""

from __future__ import annotations

from emopose.contract import MAX_REPLY_CHARS
from emopose.sentences import split_sentences
from emopose.speech.clip import EstimatedSpeech


class ReplyBound:
    def __init__(self, max_sentences: int, max_speech_s: float) -> None:
        if max_sentences < 1:
            raise ValueError(f"planner.max_sentences = {max_sentences} must be >= 1")
        if max_speech_s <= 0:
            raise ValueError(f"planner.max_speech_s = {max_speech_s} must be > 0")
        self.max_sentences, self.max_speech_s = int(max_sentences), float(max_speech_s)
        self._speech = EstimatedSpeech()

    def tally(self, max_chars: int | None = None) -> ReplyTally:
        """A fresh count for one reply (`max_chars`: the whole reply's limit, None for a streamed one)."""
        return ReplyTally(self, max_chars)

    def speech_s(self, sentence: str) -> float:
        return self._speech.synthesize(sentence).duration_s

    def bounded(self, text: str) -> str:
        """The whole reply cut to the bound at a sentence boundary (and within MAX_REPLY_CHARS)."""
        tally, kept = self.tally(MAX_REPLY_CHARS), []
        for sentence in split_sentences(" ".join(text.split())):
            if not tally.admit(sentence):
                break
            kept.append(sentence)
        reply = " ".join(kept)
        if len(reply) > MAX_REPLY_CHARS:  # one sentence longer than a reply may be: cut between words
            reply = reply[:MAX_REPLY_CHARS + 1].rsplit(" ", 1)[0].rstrip(",;:")
        return reply


class ReplyTally:
    """The sentences of one reply so far; admit(sentence) says whether it may still be said."""

    def __init__(self, bound: ReplyBound, max_chars: int | None) -> None:
        self.bound, self.max_chars = bound, max_chars
        self.sentences, self.speech_s, self.chars = 0, 0.0, 0

    def admit(self, sentence: str) -> bool:
        speech_s, chars = self.bound.speech_s(sentence), len(sentence) + (1 if self.sentences else 0)
        if self.sentences and (self.sentences >= self.bound.max_sentences
                               or self.speech_s + speech_s > self.bound.max_speech_s
                               or (self.max_chars is not None and self.chars + chars > self.max_chars)):
            return False
        self.sentences += 1
        self.speech_s += speech_s
        self.chars += chars
        return True

    @property
    def full(self) -> bool:
        """No further sentence can be admitted on the sentence count alone."""
        return self.sentences >= self.bound.max_sentences
