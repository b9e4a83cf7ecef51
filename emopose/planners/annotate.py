"""planner=annotate: any chat model speaks, the robot's own gesture planner annotates (beyond the paper).

respond mode: a chat model (any litellm model string) writes the reply as plain spoken text from the
dialogue history and the camera image (prompts/annotate.md); the annotator, the robot-side gesture
planner (planner=local by default), then plans that reply: classes, variants, intensities, and
triggers that are exact spans of it, so the say-do check holds by construction. Nothing asks the chat
model for JSON, so small or JSON-weak models become usable.
narrate mode: the line is given, so no model is asked: the annotator plans the line itself.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from typing import Any

from emopose.library import MotionLibrary
from emopose.planners.base import Planner, PlannerOutput, PlanRequest, plan_all
from emopose.planners.chat import ChatPlanner
from emopose.planners.prompting import dialogue_demonstrations

MODES = ("respond", "narrate")


class AnnotatePlanner(ChatPlanner):
    """`annotator`: a Planner, or a factory taking the library (a Hydra `_partial_` node)."""

    name = "annotate"

    def __init__(self, library: MotionLibrary, template: str, demonstrations: str,
                 annotator: Planner | Callable[..., Planner], mode: str = "respond", **kwargs: Any) -> None:
        super().__init__(library, template, demonstrations, **kwargs)
        if mode not in MODES:
            raise ValueError(f"planner.mode = {mode!r}; choose one of {MODES}")
        self.mode, self.narrates = mode, mode == "narrate"
        self.template.require("demonstrations", hint="planner=annotate uses prompts/annotate.md.")
        self._system = self.template.render(demonstrations=dialogue_demonstrations(self.demonstrations))
        self.annotator = annotator if isinstance(annotator, Planner) else annotator(library=library)

    def system_prompt(self) -> str:
        return self._system

    def check(self) -> None:
        if not self.narrates:  # narration never asks the chat model
            super().check()

    def to_contract(self, text: str, request: PlanRequest) -> str:
        """The spoken reply, planned by the annotator as a line that answers the person's words."""
        reply = " ".join(text.split())
        if not reply:
            return ""  # parse reports it as an empty answer
        heard = ({"role": "user", "content": request.utterance},)
        annotated = json.loads(self.annotator.plan(PlanRequest(reply, history=request.history + heard)).raw)
        return json.dumps({**annotated, "reply": reply})

    def plan(self, request: PlanRequest) -> PlannerOutput:
        if self.narrates:
            return self.annotator.plan(request)
        return super().plan(request)

    def plan_many(self, requests: Sequence[PlanRequest]) -> list[PlannerOutput]:
        if self.narrates:
            return plan_all(self.annotator, requests)
        return super().plan_many(requests)
