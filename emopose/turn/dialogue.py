"""The conversation the robot is having: what was said, and what of it a planner reads.

One Dialogue per run, owned by its turn runner (emopose/turn/runner.py), which every caller shares:
a turn to a person joins it as an exchange (the plan job, the web UI, a streamed reply as far as it
was spoken); the tour adds what it actually said itself (a narration line is the robot's own, a line
cut short counts as far as it was spoken, emopose/tour/runner.py). Scripted plans stay out of it.

Bounded: it keeps a window, the newest turns that fit both `HistoryWindow.turns` and `.tokens`, and
every planner reads that window as its history (the local planner the newest of it only). A turn is a
person's line with the robot's answer, or a robot line said with no one asking; older turns are dropped
whole (counted in `dropped_turns`), so a served session of any length sends a bounded prompt.
Recorded once: each message goes to the `/dialogue` channel the moment it is added, with its index in
the whole conversation ({"index", "role", "content"}); a `/request` record names only how many of the
newest messages the planner read (`history_messages`), never the messages again.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

from emopose.planners.base import PlanRequest

CHANNEL = "/dialogue"
CHARS_PER_TOKEN = 4  # a token estimate without a tokenizer: English runs 3.5-4.5 characters a token


def estimated_tokens(text: str) -> int:
    return math.ceil(len(text) / CHARS_PER_TOKEN)


@dataclass(frozen=True)
class HistoryWindow:
    """How much of the conversation a planner reads: at most `turns` turns and `tokens` (estimated) tokens."""

    turns: int = 12
    tokens: int = 2000

    def __post_init__(self) -> None:
        if self.turns < 0 or self.tokens < 0:
            raise ValueError(f"a history window needs turns >= 0 and tokens >= 0, got {self}")


@dataclass
class Dialogue:
    """Chat messages in the window, oldest first: {"role": "user" | "assistant", "content": str}."""

    window: HistoryWindow = field(default_factory=HistoryWindow)
    messages: list[dict] = field(default_factory=list)
    total: int = 0  # messages ever added: the next message's index
    dropped_turns: int = 0  # turns that left the window
    on_message: Callable[[str, dict], None] | None = None  # records (channel, message): the session's write

    def request(self, utterance: str, image: str | bytes | None = None,
                question: str | None = None) -> PlanRequest:
        """What the planner gets for the next utterance: the window as its history. `question`, a person's
        question that a prepared line answers (the tour), closes the history unanswered."""
        asked = () if question is None else (_message("user", question),)
        return PlanRequest(utterance=utterance, history=(*self.messages, *asked), image=image)

    def exchange(self, heard: str, said: str) -> None:
        """A person said `heard` and the robot answered `said`."""
        self._add(_message("user", heard), _message("assistant", said))

    def said(self, line: str) -> None:
        """A line the robot said with no one asking (a tour's narration, approach or closing)."""
        self._add(_message("assistant", line))

    def _add(self, *messages: dict) -> None:
        for message in messages:
            if self.on_message is not None:
                self.on_message(CHANNEL, {"index": self.total, **message})
            self.total += 1
            self.messages.append(message)
        self._trim()

    def _trim(self) -> None:
        """Drop the oldest turn (through its first robot line) until both bounds hold."""
        def over() -> bool:
            turns = sum(m["role"] == "assistant" for m in self.messages)
            tokens = sum(estimated_tokens(m["content"]) for m in self.messages)
            return turns > self.window.turns or tokens > self.window.tokens

        while self.messages and over():
            end = next((k for k, m in enumerate(self.messages) if m["role"] == "assistant"),
                       len(self.messages) - 1)
            del self.messages[:end + 1]
            self.dropped_turns += 1


def _message(role: str, content: str) -> dict:
    return {"role": role, "content": content}
