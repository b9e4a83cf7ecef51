"""Prompt data for the chat planners: templates, demonstrations, and the chat messages of one request.

Templates (prompts/*.md) use Python's string.Template syntax: `${name}` placeholders, `$$` for a
literal dollar sign. JSON braces need no escaping, which is why this syntax was chosen over
str.format. A leading <!-- ... --> comment documents the template and is stripped before sending.
"""

from __future__ import annotations

import base64
import json
import mimetypes
import re
import string
from dataclasses import dataclass
from pathlib import Path

from pydantic import ValidationError

from emopose.contract import GestureRecord
from emopose.planners.base import PlannerMode, PlanRequest

_HEADER_COMMENT = re.compile(r"\A\s*<!--.*?-->\s*", re.DOTALL)
_IMAGE_MAGIC = {b"\x89PNG": "image/png", b"\xff\xd8\xff": "image/jpeg", b"GIF8": "image/gif",
                b"RIFF": "image/webp"}


class PromptError(ValueError):
    """A prompt file, demonstration or request cannot be turned into messages; says which and why."""


@dataclass(frozen=True)
class PromptTemplate:
    path: Path
    text: str

    @classmethod
    def load(cls, path: str | Path, key: str = "prompt.template") -> PromptTemplate:
        path = Path(path).expanduser()
        try:
            raw = path.read_text(encoding="utf-8")
        except OSError as exc:
            raise PromptError(f"{key}: cannot read prompt template {path} ({exc.strerror})") from exc
        template = cls(path, _HEADER_COMMENT.sub("", raw, count=1))
        if not string.Template(template.text).is_valid():
            raise PromptError(f"{path}: invalid placeholder; use ${{name}}, and $$ for a literal dollar")
        return template

    @property
    def fields(self) -> set[str]:
        return set(string.Template(self.text).get_identifiers())

    def require(self, *names: str, hint: str = "") -> PromptTemplate:
        missing = sorted(set(names) - self.fields)
        if missing:
            raise PromptError(f"{self.path}: this planner needs the placeholders {missing} in its template. "
                              f"{hint}")
        return self

    def render(self, **values: object) -> str:
        try:
            return string.Template(self.text).substitute(**values)
        except KeyError as exc:
            raise PromptError(f"{self.path}: unknown placeholder ${{{exc.args[0]}}}; "
                              f"this planner fills {sorted(values)}") from exc


@dataclass(frozen=True)
class Demonstration:
    """One in-context example: an utterance, the reply, and its ordered records."""

    id: str
    text: str
    reply: str
    gestures: tuple[GestureRecord, ...]

    def plan_json(self) -> str:
        return json.dumps({"reply": self.reply, "gestures": [g.as_json() for g in self.gestures]},
                          ensure_ascii=False)


def load_demonstrations(path: str | Path, key: str = "prompt.demonstrations") -> list[Demonstration]:
    path = Path(path).expanduser()
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except OSError as exc:
        raise PromptError(f"{key}: cannot read demonstrations {path} ({exc.strerror})") from exc
    demos = []
    for number, line in enumerate(lines, start=1):
        if not line.strip():
            continue
        try:
            raw = json.loads(line)
            gestures = tuple(GestureRecord.model_validate(g) for g in raw["gestures"])
            demos.append(Demonstration(str(raw["id"]), str(raw["text"]), str(raw["reply"]), gestures))
        except (json.JSONDecodeError, KeyError, TypeError, ValidationError) as exc:
            raise PromptError(f"{path}:{number}: bad demonstration ({exc}); need id, text, reply, "
                              "gestures [{class, variant, intensity, trigger, confidence}]") from exc
    if not demos:
        raise PromptError(f"{path}: no demonstrations")
    return demos


def plan_demonstrations(demos: list[Demonstration], mode: PlannerMode = PlannerMode.NARRATE) -> str:
    """Examples for the structured prompt: the user message and the exact JSON answer.

    A demonstration is a person's message and the robot's annotated reply. In respond mode it is
    shown as such; in narrate mode the reply itself is the line to annotate (reply == line), so the
    example matches the instruction to copy the line verbatim.
    """
    shown = []
    for k, d in enumerate(demos, start=1):
        line = d.text if mode == PlannerMode.RESPOND else d.reply
        shown.append(f"Example {k}\nUser: {line}\nAnswer: {d.plan_json()}")
    return "\n\n".join(shown)


def label_demonstrations(demos: list[Demonstration]) -> str:
    """Examples for the direct-label ablation: the same annotated lines, answered with their first class."""
    labels = (d.gestures[0].cls if d.gestures else "neutral" for d in demos)
    return "\n\n".join(f"Example {k}\nUser: {d.reply}\nAnswer: {label}"
                       for k, (d, label) in enumerate(zip(demos, labels), start=1))


def dialogue_demonstrations(demos: list[Demonstration]) -> str:
    """Examples for a chat model that only talks (planner=annotate): the person's words and the reply."""
    return "\n\n".join(f"Person: {d.text}\nRobot: {d.reply}" for d in demos)


def image_data_uri(image: str | bytes) -> str:
    """An image file path or raw bytes as a base64 data URI (OpenAI image_url content part)."""
    if isinstance(image, (bytes, bytearray)):
        data = bytes(image)
        mime = next((m for magic, m in _IMAGE_MAGIC.items() if data.startswith(magic)), "image/png")
    else:
        path = Path(image).expanduser()
        try:
            data = path.read_bytes()
        except OSError as exc:
            raise PromptError(f"request image {path} is not readable ({exc.strerror})") from exc
        mime = mimetypes.guess_type(path.name)[0] or "image/png"
    return f"data:{mime};base64,{base64.b64encode(data).decode('ascii')}"


def chat_messages(system: str, request: PlanRequest) -> list[dict]:
    """System prompt, then the dialogue history as prior turns, then the utterance (+ image) last."""
    messages: list[dict] = [{"role": "system", "content": system}]
    for k, turn in enumerate(request.history):
        role, content = turn.get("role"), turn.get("content")
        if role not in ("user", "assistant") or not isinstance(content, str):
            raise PromptError(f"history[{k}] needs role user|assistant and text content, got {turn!r:.80}")
        messages.append({"role": role, "content": content})
    if request.image is None:
        messages.append({"role": "user", "content": request.utterance})
    else:
        messages.append({"role": "user", "content": [
            {"type": "text", "text": request.utterance},
            {"type": "image_url", "image_url": {"url": image_data_uri(request.image)}},
        ]})
    return messages
