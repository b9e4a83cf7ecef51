"""Parse: raw planner text -> Plan. Never raises on model output (paper, "System Boundary").

Accepts bare or fenced JSON ({"reply", "gestures": [...]}, a bare list of records, or one record),
clamps intensity to the integers 1..5 and confidence to [0, 1], maps an unknown class to neutral,
turns plain text into one neutral record, and on a JSON decode or value failure falls back to the
keyword classifier, logging that it did. Plan.source says honestly which of these happened
(emopose/contract.py, PlanSource): only "model" and "retried" are the model's own usable records.
A reply keeps up to MAX_SPOKEN_CHARS characters, the longest utterance the web UI accepts (so a narrated
line is spoken whole); a longer one, and a record's text past MAX_REPLY_CHARS, is cut at a word, never
inside one.
"""

from __future__ import annotations

import json
import logging
import math
import re
from typing import Any

from emopose import CLASSES
from emopose.contract import MAX_REPLY_CHARS, GestureRecord, Plan
from emopose.planners.base import PlannerOutput
from emopose.planners.baselines.keyword import keyword_records
from emopose.turn.model import Turn

log = logging.getLogger(__name__)

MAX_RAW_CHARS = 64_000
MAX_SPOKEN_CHARS = 2000  # the longest reply, and the input limit of serve (/api/say, the page's box)
MAX_RECORDS = 8
_FENCE = re.compile(r"```(?:json|JSON)?\s*(.*?)```", re.DOTALL)


class PlanValueError(ValueError):
    """The model's JSON decoded but a value cannot be used."""


def _json_candidate(text: str) -> str | None:
    fenced = _FENCE.search(text)
    if fenced:
        return fenced.group(1).strip()
    stripped = text.strip()
    if stripped[:1] in "{[":
        return stripped
    start = stripped.find("{")
    return stripped[start:] if start >= 0 and "}" in stripped[start:] else None


def _number(value: Any, field: str) -> float:
    if isinstance(value, bool):
        raise PlanValueError(f"{field} is a boolean")
    if isinstance(value, str):
        value = value.strip()
    try:
        number = float(value)
    except (TypeError, ValueError) as exc:
        raise PlanValueError(f"{field} is not a number: {value!r}") from exc
    if math.isnan(number):
        raise PlanValueError(f"{field} is NaN")
    return number


def cut_at_word(text: str, limit: int) -> str:
    """At most `limit` characters of `text`, ending at a word boundary (whole text when it fits)."""
    text = text.strip()
    if len(text) <= limit:
        return text
    cut = max(text.rfind(" ", 0, limit + 1), text.rfind("\n", 0, limit + 1))
    return text[:cut].rstrip() if cut > 0 else text[:limit]  # no boundary: not a word either


def _text(value: Any, limit: int = MAX_REPLY_CHARS) -> str | None:
    if value is None:
        return None
    if not isinstance(value, (str, int, float)):
        raise PlanValueError(f"expected text, got {type(value).__name__}")
    return cut_at_word(str(value), limit) or None


def _record(raw: Any) -> tuple[GestureRecord, str | None]:
    """The record, and the class the model named when it is not one of the eight (mapped to neutral)."""
    if not isinstance(raw, dict):
        raise PlanValueError(f"a gesture record must be an object, got {type(raw).__name__}")
    label = str(raw.get("class", raw.get("cls", raw.get("label", "neutral")))).strip().lower()
    unknown = None if label in CLASSES else label[:40]
    intensity = _number(raw.get("intensity", 3), "intensity")
    confidence = _number(raw.get("confidence", 1.0), "confidence")
    record = GestureRecord(
        cls="neutral" if unknown is not None else label,
        variant=_text(raw.get("variant")),
        intensity=int(min(5, max(1, round(min(max(intensity, -1e9), 1e9))))),
        trigger=_text(raw.get("trigger")),
        confidence=min(1.0, max(0.0, confidence)),
    )
    return record, unknown


def _plan_from_json(data: Any, fallback_reply: str) -> Plan:
    if isinstance(data, list):
        data = {"gestures": data}
    if not isinstance(data, dict):
        raise PlanValueError(f"top level must be an object or a list, got {type(data).__name__}")
    if "class" in data and "gestures" not in data:
        data = {"reply": data.get("reply"), "gestures": [data]}
    gestures = data.get("gestures", data.get("records", []))
    if not isinstance(gestures, list):
        raise PlanValueError("gestures must be a list")
    reply = _text(data.get("reply"), MAX_SPOKEN_CHARS) if data.get("reply") is not None else None
    records, notes, source = [], [], "model"
    for raw in gestures[:MAX_RECORDS]:
        record, unknown = _record(raw)
        records.append(record)
        if unknown is not None:
            notes.append(f"unknown class {unknown!r} mapped to neutral")
            source = "unknown_class"
    if len(gestures) > MAX_RECORDS:
        notes.append(f"kept the first {MAX_RECORDS} of {len(gestures)} records")
    if not records:
        records.append(GestureRecord(cls="neutral"))
        notes.append("no gesture records; used one neutral record")
        source = "no_records"
    return Plan(reply=reply or fallback_reply, records=tuple(records), source=source, notes=tuple(notes))


def parse_plan(raw: str | None, utterance: str = "", line: str | None = None) -> Plan:
    """The parser. `utterance` is the reply used when the model gives none (narration mode); `line`, when
    given, is what the robot must say whatever the answer, so plain text never replaces it."""
    text = (raw or "")[:MAX_RAW_CHARS]
    if not text.strip():
        return Plan(reply=line or utterance, records=(GestureRecord(cls="neutral"),), source="empty",
                    notes=("empty model output; one neutral record",))
    candidate = _json_candidate(text)
    if candidate is None:
        return Plan(reply=line or cut_at_word(text, MAX_SPOKEN_CHARS),
                    records=(GestureRecord(cls="neutral"),), source="plain_text",
                    notes=("plain-text answer; one neutral record",))
    try:
        return _plan_from_json(json.loads(candidate), utterance)
    except (json.JSONDecodeError, PlanValueError, RecursionError, ValueError) as exc:
        log.warning("model output unusable (%s); keyword fallback", str(exc)[:200])
        source_text = line or utterance or text
        return Plan(reply=line or utterance or cut_at_word(text, MAX_SPOKEN_CHARS),
                    records=tuple(keyword_records(source_text)), source="keyword_fallback",
                    notes=(f"keyword fallback: {str(exc)[:200]}",))


def parse_output(output: PlannerOutput, utterance: str = "") -> Plan:
    """A planner's output as a Plan whose source is the truth: a failed call's keyword answer is
    call_failed (never "model"), and a usable answer that needed retries is "retried"."""
    plan = parse_plan(output.raw, utterance, output.line)
    if output.fallback:
        return plan.model_copy(update={"source": "call_failed",
                                       "notes": (*plan.notes, f"planner call failed: {output.error}")})
    if plan.source == "model" and output.meta.get("attempts", 1) > 1:
        return plan.model_copy(update={"source": "retried"})
    return plan


class Parse:
    """Stage: planner_output -> plan."""

    name = "parse"
    reads = ("request", "planner_output")
    writes = ("plan",)

    def __call__(self, turn: Turn) -> Plan:
        return parse_output(turn.planner_output, turn.request.utterance)
