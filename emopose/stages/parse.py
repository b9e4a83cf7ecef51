"""Parse: raw planner text -> Plan. Never raises on model output (paper, "System Boundary").

Accepts bare or fenced JSON ({"reply", "gestures": [...]}, a bare list of records, or one record),
clamps intensity to the integers 1..5 and confidence to [0, 1], maps an unknown class to neutral,
turns plain text into one neutral record, and on a JSON decode or value failure falls back to the
keyword classifier, logging that it did.
"""

from __future__ import annotations

import json
import logging
import math
import re
from typing import Any

from emopose import CLASSES
from emopose.contract import GestureRecord, Plan
from emopose.planners.keyword import keyword_records
from emopose.turn import Turn

log = logging.getLogger(__name__)

MAX_RAW_CHARS = 64_000
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


def _text(value: Any) -> str | None:
    if value is None:
        return None
    if not isinstance(value, (str, int, float)):
        raise PlanValueError(f"expected text, got {type(value).__name__}")
    text = str(value).strip()
    return text[:200] or None


def _record(raw: Any) -> tuple[GestureRecord, list[str]]:
    if not isinstance(raw, dict):
        raise PlanValueError(f"a gesture record must be an object, got {type(raw).__name__}")
    notes = []
    label = str(raw.get("class", raw.get("cls", raw.get("label", "neutral")))).strip().lower()
    if label not in CLASSES:
        notes.append(f"unknown class {label[:40]!r} mapped to neutral")
        label = "neutral"
    intensity = _number(raw.get("intensity", 3), "intensity")
    confidence = _number(raw.get("confidence", 1.0), "confidence")
    record = GestureRecord(
        cls=label,
        variant=_text(raw.get("variant")),
        intensity=int(min(5, max(1, round(min(max(intensity, -1e9), 1e9))))),
        trigger=_text(raw.get("trigger")),
        confidence=min(1.0, max(0.0, confidence)),
    )
    return record, notes


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
    reply = _text(data.get("reply")) if data.get("reply") is not None else None
    records, notes = [], []
    for raw in gestures[:MAX_RECORDS]:
        record, record_notes = _record(raw)
        records.append(record)
        notes.extend(record_notes)
    if len(gestures) > MAX_RECORDS:
        notes.append(f"kept the first {MAX_RECORDS} of {len(gestures)} records")
    if not records:
        records.append(GestureRecord(cls="neutral"))
        notes.append("no gesture records; used one neutral record")
    return Plan(reply=reply or fallback_reply, records=tuple(records), source="model", notes=tuple(notes))


def parse_plan(raw: str | None, utterance: str = "") -> Plan:
    """The parser. `utterance` is the reply used when the model gives none (narration mode)."""
    text = (raw or "")[:MAX_RAW_CHARS]
    if not text.strip():
        return Plan(reply=utterance, records=(GestureRecord(cls="neutral"),), source="empty",
                    notes=("empty model output; one neutral record",))
    candidate = _json_candidate(text)
    if candidate is None:
        return Plan(reply=text.strip()[:2000], records=(GestureRecord(cls="neutral"),), source="plain_text")
    try:
        return _plan_from_json(json.loads(candidate), utterance)
    except (json.JSONDecodeError, PlanValueError, RecursionError, ValueError) as exc:
        log.warning("model output unusable (%s); keyword fallback", str(exc)[:200])
        source_text = utterance or text
        return Plan(reply=utterance or text.strip()[:2000], records=tuple(keyword_records(source_text)),
                    source="keyword_fallback", notes=(f"keyword fallback: {str(exc)[:200]}",))


class Parse:
    """Stage: planner_output -> plan."""

    name = "parse"
    reads = ("request", "planner_output")
    writes = ("plan",)

    def __call__(self, turn: Turn) -> Plan:
        return parse_plan(turn.planner_output.raw, turn.request.utterance)
