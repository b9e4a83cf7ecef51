"""planner=llm: the paper's full structured planner (GPT-class chat model through litellm).

The system prompt is prompts/structured.md rendered with the live library guide, the in-context
demonstrations, the plan-length limit and the mode; the dialogue history follows as prior turns and
the utterance (with an optional camera image) comes last. The model's answer is returned untouched
as raw contract JSON: validating it is the parse stage's job, the one edge for model output.
"""

from __future__ import annotations

from typing import Any

from emopose.library import MotionLibrary
from emopose.planners.chat import ChatPlanner
from emopose.planners.guide import library_guide
from emopose.planners.prompting import plan_demonstrations

MODES = ("narrate", "respond")


class LLMPlanner(ChatPlanner):
    """mode=narrate: the utterance is the robot's own line (reply = utterance; the benchmarks).
    mode=respond: the utterance is a person speaking to the robot, which answers (dialogue, tour Q&A)."""

    name = "llm"

    def __init__(self, library: MotionLibrary, template: str, demonstrations: str, mode: str = "narrate",
                 max_gestures: int = 4, **kwargs: Any) -> None:
        super().__init__(library, template, demonstrations, **kwargs)
        if mode not in MODES:
            raise ValueError(f"planner.mode = {mode!r}; choose one of {MODES}")
        if not 1 <= max_gestures <= 8:
            raise ValueError(f"planner.max_gestures = {max_gestures} must be in 1..8")
        self.mode, self.max_gestures = mode, int(max_gestures)
        self.template.require("library_guide", "demonstrations", hint="planner=llm goes with prompt=structured.")
        self._examples = plan_demonstrations(self.demonstrations, mode)
        self.system_prompt()  # render once now, so a template error surfaces at build time

    def system_prompt(self) -> str:
        # Rendered per request from the cached guide: a variant saved after construction is offered
        # on the very next call (library_guide re-renders when library.version changes).
        return self.template.render(library_guide=library_guide(self.library), demonstrations=self._examples,
                                    max_gestures=self.max_gestures, mode=self.mode)
