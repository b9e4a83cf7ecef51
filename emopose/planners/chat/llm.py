"""planner=llm: the paper's full structured planner (GPT-class chat model through litellm).

The system prompt is a template from prompts/ rendered with the live library guide, the in-context
demonstrations, the plan-length limit and the mode; the dialogue history follows as prior turns and
the utterance (with an optional camera image) comes last. The template picks the guide's form by its
placeholder: ${library_guide} (a line per motion, prompts/structured.md) or ${library_names} (a line
per class, prompts/compact.md for small local models).

Structured output (planner.structured_output): the answer's JSON schema (emopose.contract.plan_schema,
the eight classes and the live variant names as enums) goes out as response_format in the form the
server takes (emopose/llm/formats.py: json_schema, json_object_schema for llama-cpp-python, json_object,
none). check() identifies the server and probes the forms best first, noting each refused one; the
form found is used for every item and named in the planner's stats (results.json). Without a probe
(planner.client.probe=false, or plan() before check()) "auto" is what litellm reports for a hosted
model and json_schema for a server at api_base.
The answer is returned untouched as raw contract JSON: validating it is the parse stage's job, the one
edge for model output.
"""

from __future__ import annotations

from emopose.contract import plan_schema
from emopose.library import MotionLibrary
from emopose.llm.client import LLMClient
from emopose.llm.errors import litellm_module
from emopose.llm.formats import SERVER_FORMS, SETTINGS, candidates, response_format
from emopose.llm.server import Endpoint
from emopose.planners.base import ModalPlanner, PlannerMode
from emopose.planners.chat.guide import library_guide
from emopose.planners.chat.planner import ChatPlanner
from emopose.planners.chat.prompting import PromptError, plan_demonstrations

GUIDES = {"library_guide": "full", "library_names": "short"}  # placeholder -> guide form


def supported_structured_output(model: str) -> str:
    """What litellm reports the model accepts: json_schema, json_object, or none."""
    litellm = litellm_module()
    try:
        if litellm.supports_response_schema(model=model):
            return "json_schema"
        _, provider, _, _ = litellm.get_llm_provider(model=model)
        params = litellm.get_supported_openai_params(model=model, custom_llm_provider=provider) or []
    except Exception:  # noqa: BLE001 - a model litellm cannot describe: ask in the prompt only
        return "none"
    return "json_object" if "response_format" in params else "none"


class LLMPlanner(ChatPlanner, ModalPlanner):
    """mode=narrate: the utterance is the robot's own line (reply = utterance; the benchmarks).
    mode=respond: the utterance is a person speaking to the robot, which answers (dialogue, tour Q&A).
    The system prompt offers the live library's motions."""

    name = "llm"

    def __init__(self, library: MotionLibrary, client: LLMClient, template: str, demonstrations: str,
                 mode: str = "narrate", max_gestures: int = 4, structured_output: str = "auto",
                 max_demonstrations: int | None = None) -> None:
        super().__init__(client, template, demonstrations, max_demonstrations)
        if not 1 <= max_gestures <= 8:
            raise ValueError(f"planner.max_gestures = {max_gestures} must be in 1..8")
        if structured_output not in SETTINGS:
            raise ValueError(f"planner.structured_output = {structured_output!r}; choose one of {SETTINGS}")
        self.library, self.mode, self.max_gestures = library, PlannerMode.parse(mode), int(max_gestures)
        self.narrates = self.mode is PlannerMode.NARRATE
        self.template.require("demonstrations",
                              hint="planner=llm goes with prompt=structured or prompt=compact.")
        self._guides = {form for name, form in GUIDES.items() if name in self.template.fields}
        if not self._guides:
            raise PromptError(f"{self.template.path}: planner=llm needs ${{library_guide}} or "
                              "${library_names}")
        self._examples = plan_demonstrations(self.demonstrations, self.mode)
        self._setting, self._unchecked_form = structured_output, None
        self._schema: tuple[int, dict] | None = None  # (library version, schema)
        self.system_prompt()  # render once now, so a template error surfaces at build time

    def system_prompt(self) -> str:
        # Rendered per request from the cached guide: a variant saved after construction is offered
        # on the very next call (library_guide re-renders when library.version changes).
        guides = {name: library_guide(self.library, form) for name, form in GUIDES.items()
                  if form in self._guides}
        return self.template.render(**guides, demonstrations=self._examples, max_gestures=self.max_gestures,
                                    mode=self.mode.value)

    @property
    def structured_output(self) -> str:
        """The form sent: what check() found the server takes; unprobed, the setting (auto: what litellm
        reports for a hosted model, json_schema for a server at api_base)."""
        if self.endpoint is not None and self.endpoint.structured_output:
            return self.endpoint.structured_output
        if self._unchecked_form is None:
            self._unchecked_form = self.format_offers(Endpoint("unchecked"))[0][0]
        return self._unchecked_form

    def format_offers(self, server: Endpoint) -> list[tuple[str, dict | None]]:
        kind = "openai-compatible" if server.kind == "unchecked" and self.client.api_base else server.kind
        asks_litellm = self._setting == "auto" and kind not in SERVER_FORMS
        reported = supported_structured_output(self.client.model) if asks_litellm else "none"
        return [(form, self._format(form)) for form in candidates(self._setting, kind, reported)]

    def response_format(self) -> dict | None:
        return self._format(self.structured_output)

    def _format(self, form: str) -> dict | None:
        return response_format(form, self.answer_schema()) if form != "none" else None

    def answer_schema(self) -> dict:
        """plan_schema for the library's current version (rebuilt when a motion is saved)."""
        snapshot = self.library.snapshot
        if self._schema is None or self._schema[0] != snapshot.version:
            names = [n for n in snapshot.entries if n != snapshot.neutral] or list(snapshot.entries)
            self._schema = (snapshot.version, plan_schema(names, self.max_gestures))
        return self._schema[1]
