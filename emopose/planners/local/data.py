"""Training examples for the local planner: utterances cut into gold acts over candidate segments.

Every example is a text with its ordered acts (character span + class) and anchor spans. Acts are
unions of contiguous candidate segments (planners/segment.py), so training sees exactly the boundaries
the planner can choose at run time:

- a single-act item is one act over all its segments (every candidate boundary is "same act");
- a multi-act item assigns each segment to the annotated anchor it contains; a segment with no anchor
  joins the act before it (or the first act, at the start);
- synthetic sequences join 2-4 single-act training items of different classes with varied joiners
  ("; ", ", but ", ". ", ...), so the boundary model sees many more act changes than the hand-written
  sequences alone hold;
- a dialogue item (train/context/) is one act over its final utterance, read after its history;
- distractors give training items (single- and multi-act, synthetic too) the history of an unrelated
  dialogue, labels unchanged and marked unrelated, so the model learns that a history which does not
  bear on the utterance must sway neither its classes nor its split, and to tell such a history from
  one that does (the relevance head; a dialogue item's own history bears on it).

Items whose id hashes into the held-out bucket never enter training (the quality check scores them).
"""

from __future__ import annotations

import hashlib
import json
import random
from dataclasses import dataclass, field, replace
from pathlib import Path

from emopose import CLASSES
from emopose.planners.local.segment import Segment, segments


@dataclass(frozen=True)
class Act:
    start: int
    end: int
    label: str


@dataclass
class Example:
    id: str
    text: str
    acts: list[Act]
    pieces: list[Segment]
    anchors: list[tuple[int, int]] = field(default_factory=list)  # empty: no anchor supervision
    variants: list[str] = field(default_factory=list)  # annotated motion per act; empty: none
    history: tuple[dict, ...] = ()  # dialogue turns before the text (spans are in the text alone)
    history_bears: bool = True  # False for a distractor: the history is another dialogue's

    @property
    def boundaries(self) -> list[int]:
        """For each candidate boundary (before pieces[1:]): 1 when a new act starts there."""
        starts = {a.start for a in self.acts}
        return [int(p.start in starts) for p in self.pieces[1:]]

    def gold_split(self) -> list[tuple[tuple[int, int], str]] | None:
        """The acts as (segment range [i, j), class), or None when neighbouring acts share a class
        (the split model forbids that)."""
        if any(a.label == b.label for a, b in zip(self.acts, self.acts[1:])):
            return None
        first = {p.start: k for k, p in enumerate(self.pieces)}
        last = {p.end: k for k, p in enumerate(self.pieces)}
        return [((first[a.start], last[a.end] + 1), a.label) for a in self.acts]


def is_held_out(item_id: str, percent: int) -> bool:
    """A stable split by id: the same items are held out on every machine and run."""
    return int(hashlib.sha256(item_id.encode()).hexdigest(), 16) % 100 < percent


def single_act(item_id: str, text: str, label: str, history: tuple[dict, ...] = ()) -> Example:
    pieces = segments(text) or [Segment(text, 0, len(text), True)]
    return Example(item_id, text, [Act(pieces[0].start, pieces[-1].end, label)], pieces, history=history)


def multi_act(row: dict) -> Example | None:
    """The annotated acts of a sequence item, or None when two anchors share one segment."""
    text = row["text"]
    pieces = segments(text)
    positions = [text.find(a) for a in row["anchors"]]
    owner: list[int | None] = []
    for piece in pieces:
        inside = [k for k, pos in enumerate(positions) if piece.start <= pos < piece.end]
        if len(inside) > 1:
            return None
        owner.append(inside[0] if inside else None)
    if sorted(k for k in owner if k is not None) != list(range(len(positions))):
        return None
    current = 0
    for i, k in enumerate(owner):
        current = k if k is not None else current
        owner[i] = current
    acts = []
    for k, label in enumerate(row["labels"]):
        mine = [p for p, o in zip(pieces, owner) if o == k]
        acts.append(Act(mine[0].start, mine[-1].end, label))
    anchors = [(pos, pos + len(a)) for pos, a in zip(positions, row["anchors"])]
    return Example(row["id"], text, acts, pieces, anchors, list(row.get("variants", [])))


# (joiner, whether the next part continues the sentence: its first letter is lowered)
_JOINERS = [(". ", False), ("! ", False), ("? ", False), ("... ", False), ("; ", True), (" - ", True),
            (", and ", True), (", but ", True), (", so ", True), (" and ", True), (", then ", True),
            (", ", True), (": ", True)]


def synthetic_sequence(parts: list[Example], rng: random.Random, item_id: str) -> Example | None:
    """Join single-act examples into one utterance; acts follow the parts. None when a part has no
    segment of its own (a joiner merged it into a neighbour's), so no act boundary can be placed."""
    text, spans = "", []
    for k, part in enumerate(parts):
        body = part.text.strip()
        if k:
            joiner, continues = rng.choice(_JOINERS)
            if continues:
                text = text.rstrip(".!? ")
                if not body.startswith(("I ", "I'")):
                    body = body[0].lower() + body[1:]
                text += joiner
            else:  # a sentence break: keep the part's own end punctuation when it has one
                text += " " if text[-1] in ".!?" else joiner
        spans.append((len(text), len(text) + len(body)))
        text += body
    pieces = segments(text)

    def part_of(piece: Segment) -> int:  # a piece's last character decides (joiner words lead pieces)
        return max(k for k, (start, _) in enumerate(spans) if start <= piece.end - 1)

    acts = []
    for k, part in enumerate(parts):
        mine = [p for p in pieces if part_of(p) == k]
        if not mine:
            return None
        acts.append(Act(mine[0].start, mine[-1].end, part.acts[0].label))
    return Example(item_id, text, acts, pieces)


def synthetic_sequences(singles: list[Example], count: int, seed: int) -> list[Example]:
    """`count` joined sequences of 2 (25%), 3 (50%) or 4 (25%) acts, neighbouring classes distinct."""
    rng = random.Random(seed)
    by_class: dict[str, list[Example]] = {}
    for example in singles:
        by_class.setdefault(example.acts[0].label, []).append(example)
    out = []
    for n in range(count):
        length = rng.choice((2, 3, 3, 4))
        labels: list[str] = []
        while len(labels) < length:
            label = rng.choice(sorted(by_class))
            if not labels or label != labels[-1]:
                labels.append(label)
        example = synthetic_sequence([rng.choice(by_class[c]) for c in labels], rng, f"synthetic-{n}")
        if example is not None:
            out.append(example)
    return out


def context_distractors(items: list[Example], dialogues: list[Example], count: int,
                        seed: int) -> list[Example]:
    """`count` examples drawn from items (single- and multi-act, no history), each after the history of
    a randomly drawn dialogue; acts, anchors and variants unchanged."""
    rng = random.Random(seed)
    if not items or not dialogues:
        return []
    return [replace(item, id=f"distractor-{n}", history=rng.choice(dialogues).history, history_bears=False)
            for n, item in enumerate(rng.choices(items, k=count))]


def load_examples(paths: list[str], holdout_percent: int, held_out: bool = False,
                  synthetic: int = 0, distractors: int = 0, seed: int = 0) -> list[Example]:
    """Training examples (held_out=False, plus `synthetic` joined sequences and `distractors` items
    after unrelated dialogues) or the held-out slice."""
    examples: list[Example] = []
    for path in paths:
        for line in Path(path).read_text().splitlines():
            if not line.strip():
                continue
            row = json.loads(line)
            if is_held_out(row["id"], holdout_percent) != held_out:
                continue
            if "label" in row:
                example = single_act(row["id"], row["text"], row["label"], tuple(row.get("history", ())))
            else:
                example = multi_act(row)
            if example is not None:
                examples.append(example)
    bad = {a.label for e in examples for a in e.acts} - set(CLASSES)
    if bad:
        raise ValueError(f"training labels {sorted(bad)} are not among {CLASSES}")
    if not held_out:
        singles = [e for e in examples if len(e.acts) == 1 and not e.history]
        examples += synthetic_sequences(singles, synthetic, seed) if synthetic else []
        dialogues = [e for e in examples if e.history]
        examples += context_distractors([e for e in examples if not e.history], dialogues, distractors, seed)
    return examples
