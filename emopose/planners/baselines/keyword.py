"""The paper's keyword-rule baseline, also the parser's fallback classifier.

Cues are matched case-insensitively on word boundaries; every match becomes one record, in the order
the cues occur in the text, with the matched phrase as its trigger. No match yields one neutral record.
"""

from __future__ import annotations

import json
import re
from functools import lru_cache

from emopose.contract import GestureRecord
from emopose.planners.base import PlannerOutput, PlanRequest, timed

KEYWORD_CUES: dict[str, tuple[str, ...]] = {
    "pointing": ("look at", "over there", "over here", "this one", "that one", "on your left",
                 "on your right", "to the left", "to the right", "point", "there is", "see the"),
    "emphasizing": ("important", "crucial", "key", "really", "very", "must", "essential",
                    "remember", "listen", "definitely"),
    "rejecting": ("no", "not", "never", "don't", "do not", "stop", "refuse", "can't", "cannot",
                  "won't", "wrong", "reject"),
    "agreeing": ("yes", "agree", "exactly", "right", "correct", "sure", "absolutely", "of course",
                 "okay", "sounds good"),
    "doubting": ("maybe", "perhaps", "not sure", "doubt", "really?", "i wonder", "unsure", "might",
                 "hmm", "suppose"),
    "welcoming": ("welcome", "hello", "hi", "hey", "good morning", "nice to meet", "come in",
                  "glad you", "greetings", "goodbye"),
    "comforting": ("sorry", "it's okay", "don't worry", "it will be fine", "i understand",
                   "take your time", "be alright", "here for you", "calm"),
    "neutral": (),
}


@lru_cache(maxsize=1)
def _cue_pattern() -> re.Pattern[str]:
    alternatives = []
    for cls, cues in KEYWORD_CUES.items():
        for k, cue in enumerate(sorted(cues, key=len, reverse=True)):
            alternatives.append(f"(?P<{cls}_{k}>{re.escape(cue)})")
    # Longest cues first within the alternation so "not sure" beats "not"; word boundaries on both sides.
    alternatives.sort(key=lambda a: -len(a))
    return re.compile(r"(?<![\w'])(?:" + "|".join(alternatives) + r")(?![\w'])", re.IGNORECASE)


def keyword_records(text: str, max_records: int = 4) -> list[GestureRecord]:
    """Ordered records for every cue found in text; one neutral record when nothing matches."""
    records: list[GestureRecord] = []
    for match in _cue_pattern().finditer(text):
        cls = match.lastgroup.rsplit("_", 1)[0]
        if records and records[-1].cls == cls:
            continue
        records.append(GestureRecord(cls=cls, trigger=match.group(0), confidence=0.5))
        if len(records) == max_records:
            break
    return records or [GestureRecord(cls="neutral", confidence=0.5)]


class KeywordPlanner:
    """planner=keyword: fixed keyword rules; the reply is the input text (narration mode)."""

    name = "keyword"
    sampled = False

    def __init__(self, max_records: int = 4) -> None:
        self.max_records = max_records

    def plan(self, request: PlanRequest) -> PlannerOutput:
        with timed() as clock:
            records = keyword_records(request.utterance, self.max_records)
            raw = json.dumps({"reply": request.utterance, "gestures": [r.as_json() for r in records]})
        return PlannerOutput(raw=raw, latency_s=clock.elapsed)
