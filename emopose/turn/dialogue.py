"""The conversation the robot is having: what was said, and what of it a planner reads.

One Dialogue per run, owned by its turn runner (emopose/turn/runner.py), which every caller shares:
a turn to a person joins it as an exchange (the plan job, the web UI, a streamed reply as far as it
was spoken); the tour adds what it actually said itself (a narration line is the robot's own, a line
cut short counts as far as it was spoken, emopose/tour/runner.py). Scripted plans stay out of it.
It is kept whole for the run, with no bound: a run is one conversation (a tour, a served session),
and each planner reads what it can use of it (the local planner its newest turns only).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from emopose.planners.base import PlanRequest


@dataclass
class Dialogue:
    """Chat messages, oldest first: {"role": "user" | "assistant", "content": str}."""

    messages: list[dict] = field(default_factory=list)

    def request(self, utterance: str, image: str | bytes | None = None,
                question: str | None = None) -> PlanRequest:
        """What the planner gets for the next utterance: the dialogue so far as its history. `question`, a
        person's question that a prepared line answers (the tour), closes the history unanswered."""
        asked = () if question is None else (_message("user", question),)
        return PlanRequest(utterance=utterance, history=(*self.messages, *asked), image=image)

    def exchange(self, heard: str, said: str) -> None:
        """A person said `heard` and the robot answered `said`."""
        self.messages += [_message("user", heard), _message("assistant", said)]

    def said(self, line: str) -> None:
        """A line the robot said with no one asking (a tour's narration, approach or closing)."""
        self.messages.append(_message("assistant", line))


def _message(role: str, content: str) -> dict:
    return {"role": role, "content": content}
