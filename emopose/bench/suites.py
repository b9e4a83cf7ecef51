"""Loading the evaluation suites (JSONL) with validation at the edge.

Three formats (see experiments/README and the spec): the single-label benchmark
{"id", "text", "label", "tier"}, the context suite {"id", "history", "text", "label"} and the sequence
suite {"id", "text", "labels", "anchors", "variants"} (planned by sequence_suite, and measured as
annotated plans by sync_eval). A malformed file is refused with a SuiteError that names the file, the
line and the field, and says what is allowed. Blank lines are skipped.
"""

from __future__ import annotations

import json
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path

from emopose import CLASSES
from emopose.contract import GestureRecord, Plan

TIERS: tuple[str, ...] = ("easy", "medium", "hard")
ROLES = ("user", "assistant")


class SuiteError(ValueError):
    """A suite file is malformed; the message is 'file:line: field 'x': problem'."""

    def __init__(self, path: Path, line: int, field: str | None, problem: str) -> None:
        where = f"{path}:{line}" + (f": field '{field}'" if field else "")
        super().__init__(f"{where}: {problem}")
        self.path, self.line, self.field = path, line, field


@dataclass(frozen=True)
class BenchItem:
    id: str
    text: str
    label: str
    tier: str


@dataclass(frozen=True)
class ContextItem:
    id: str
    history: tuple[dict, ...]
    text: str
    label: str


@dataclass(frozen=True)
class SequenceItem:
    id: str
    text: str
    labels: tuple[str, ...]
    anchors: tuple[str, ...]
    variants: tuple[str, ...]

    @property
    def spans(self) -> list[tuple[int, int]]:
        """Character spans of the anchors, found left to right (each after the previous one's end)."""
        return anchor_spans(self.text, self.anchors)

    def plan(self) -> Plan:
        """The annotation as the planner's answer: the reply is the text, one record per label."""
        records = tuple(GestureRecord(cls=c, variant=v, trigger=a) for c, a, v in
                        zip(self.labels, self.anchors, self.variants))
        return Plan(reply=self.text, records=records, source="scripted", notes=("sync_eval annotation",))


def anchor_spans(text: str, anchors: tuple[str, ...] | list[str]) -> list[tuple[int, int]]:
    spans, start = [], 0
    for k, anchor in enumerate(anchors):
        at = text.find(anchor, start) if anchor else -1
        if at < 0:
            raise ValueError(f"anchors[{k}] {anchor!r} does not occur in text after the previous anchor")
        spans.append((at, at + len(anchor)))
        start = at + len(anchor)
    return spans


def _records(path: Path) -> Iterator[tuple[int, dict]]:
    if not path.is_file():
        raise FileNotFoundError(f"suite file {path} does not exist (set bench.path=...)")
    with path.open(encoding="utf-8") as f:
        for line_no, line in enumerate(f, start=1):
            if not line.strip():
                continue
            try:
                obj = json.loads(line)
            except json.JSONDecodeError as exc:
                problem = f"not valid JSON ({exc.msg}, column {exc.colno})"
                raise SuiteError(path, line_no, None, problem) from exc
            if not isinstance(obj, dict):
                raise SuiteError(path, line_no, None, f"expected a JSON object, got {type(obj).__name__}")
            yield line_no, obj


class _Checker:
    """Field checks for one record; every failure names file, line and field."""

    def __init__(self, path: Path, line: int, obj: dict, seen_ids: set[str]) -> None:
        self.path, self.line, self.obj = path, line, obj
        ident = self.text("id")
        if ident in seen_ids:
            self.fail("id", f"duplicate id {ident!r}; ids must be unique within a suite")
        seen_ids.add(ident)
        self.id = ident

    def fail(self, field: str, problem: str):
        raise SuiteError(self.path, self.line, field, problem)

    def get(self, field: str):
        if field not in self.obj:
            self.fail(field, "missing (required)")
        return self.obj[field]

    def text(self, field: str) -> str:
        value = self.get(field)
        if not isinstance(value, str) or not value.strip():
            self.fail(field, f"must be a non-empty string, got {value!r}")
        return value

    def choice(self, field: str, allowed: tuple[str, ...], value=None) -> str:
        value = self.get(field) if value is None else value
        if value not in allowed:
            self.fail(field, f"unknown value {value!r}; allowed: {', '.join(allowed)}")
        return value

    def strings(self, field: str) -> tuple[str, ...]:
        value = self.get(field)
        if not isinstance(value, list) or not value or not all(isinstance(v, str) and v for v in value):
            self.fail(field, f"must be a non-empty list of non-empty strings, got {value!r}")
        return tuple(value)


def load_bench(path: str | Path, tiers: tuple[str, ...] | list[str] | None = None) -> list[BenchItem]:
    """Benchmark items, optionally only those of the given tiers (file order kept)."""
    path, seen, items = Path(path), set(), []
    for line, obj in _records(path):
        c = _Checker(path, line, obj, seen)
        item = BenchItem(c.id, c.text("text"), c.choice("label", CLASSES), c.choice("tier", TIERS))
        items.append(item)
    wanted = set(tiers or TIERS)
    return [i for i in items if i.tier in wanted]


def load_context(path: str | Path) -> list[ContextItem]:
    path, seen, items = Path(path), set(), []
    for line, obj in _records(path):
        c = _Checker(path, line, obj, seen)
        history = c.get("history")
        if not isinstance(history, list):
            c.fail("history", "must be a list of {role, content} turns (may be empty)")
        for k, turn in enumerate(history):
            if not isinstance(turn, dict) or turn.get("role") not in ROLES \
                    or not isinstance(turn.get("content"), str) or not turn["content"].strip():
                c.fail(f"history[{k}]", f"must be {{'role': one of {ROLES}, 'content': non-empty text}}, "
                                        f"got {turn!r}")
        history = tuple({"role": t["role"], "content": t["content"]} for t in history)
        items.append(ContextItem(c.id, history, c.text("text"), c.choice("label", CLASSES)))
    return items


def load_sequence(path: str | Path, variant_classes: Mapping[str, str] | None = None,
                  anchors_in_text: bool = True) -> list[SequenceItem]:
    """Sequence items; with `variant_classes` (motion name -> class) variants are checked against it.
    `anchors_in_text=False` accepts an anchor that is not in the text (sync_eval's say-do check
    measures such items and reports the missing trigger)."""
    path, seen, items = Path(path), set(), []
    for line, obj in _records(path):
        c = _Checker(path, line, obj, seen)
        text = c.text("text")
        labels, anchors, variants = c.strings("labels"), c.strings("anchors"), c.strings("variants")
        for k, label in enumerate(labels):
            c.choice(f"labels[{k}]", CLASSES, label)
        if not len(labels) == len(anchors) == len(variants):
            c.fail("anchors", f"labels, anchors and variants must have equal lengths, got "
                              f"{len(labels)}, {len(anchors)}, {len(variants)}")
        if anchors_in_text:
            try:
                anchor_spans(text, anchors)
            except ValueError as exc:
                c.fail("anchors", f"{exc}; anchors must be exact substrings of text, in label order")
        if variant_classes is not None:
            for k, (variant, label) in enumerate(zip(variants, labels)):
                if variant not in variant_classes:
                    c.fail(f"variants[{k}]", f"{variant!r} is not a motion in the library")
                if variant_classes[variant] != label:
                    c.fail(f"variants[{k}]", f"{variant!r} is a {variant_classes[variant]} motion, "
                                             f"but labels[{k}] is {label!r}")
        items.append(SequenceItem(c.id, text, labels, anchors, variants))
    return items
