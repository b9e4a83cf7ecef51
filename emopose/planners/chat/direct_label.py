"""planner=direct_label: the paper's interface ablation ("Direct-label GPT-5.5").

Same model, client, sampling, cache, dialogue history and demonstrations as planner=llm, but the
prompt (prompts/direct_label.md) keeps only the class definitions and asks for one class label:
no priority rules, no library guide, no record schema. The label becomes one contract record
(variant left to the resolver's class default), so the rest of the pipeline is unchanged. An
answer without a label is passed on as it came, so the parser reports it (plain_text, a fallback)
instead of a silent neutral.
"""

from __future__ import annotations

import json
import re

from emopose import CLASSES
from emopose.llm.client import LLMClient
from emopose.planners.base import PlanRequest
from emopose.planners.chat.planner import ChatPlanner
from emopose.planners.chat.prompting import label_demonstrations

_LABEL = re.compile(r"\b(" + "|".join(CLASSES) + r")\b", re.IGNORECASE)


def label_from_answer(text: str) -> str | None:
    """The first class name in the answer ("Comforting.", "Label: agreeing"); None if there is none."""
    match = _LABEL.search(text or "")
    return match.group(1).lower() if match else None


class DirectLabelPlanner(ChatPlanner):
    name = "direct_label"

    def __init__(self, client: LLMClient, template: str, demonstrations: str,
                 max_demonstrations: int | None = None) -> None:
        super().__init__(client, template, demonstrations, max_demonstrations)
        self.template.require("labels", hint="planner=direct_label goes with prompt=direct_label.")
        # The prompt does not depend on the library, so it is rendered once.
        self._system = self.template.render(labels=", ".join(CLASSES),
                                            demonstrations=label_demonstrations(self.demonstrations))

    def system_prompt(self) -> str:
        return self._system

    def to_contract(self, text: str, request: PlanRequest) -> str:
        label = label_from_answer(text)
        if label is None:
            return text
        record = {"class": label, "variant": None, "intensity": 3, "trigger": None, "confidence": 1.0}
        return json.dumps({"reply": request.utterance, "gestures": [record]})
