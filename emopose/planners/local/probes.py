"""Which probe utterances a new motion would take, and from which motion, before it is saved (issue 29).

A motion added by file or in Pose Studio competes with the motions already there through its description
and its `examples:` (planners/local/variants.py): a description that reaches beyond its own acts ("a
salute ... for greetings") takes acts of motions that fit them better. library/probes.yaml ships a few
utterances per intent; probe_moves plans each with the live library and with the candidate added (the
library itself is not touched) and lists every act whose motion becomes the candidate, so the author can
tighten the description, or add examples, before saving.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from pathlib import Path

import yaml

from emopose import CLASSES
from emopose.config import PROJECT_ROOT
from emopose.contract import LibraryEntry
from emopose.planners.local.catalogue import motion_evidence
from emopose.planners.local.planner import LocalPlanner
from emopose.planners.local.variants import VariantChooser

PROBES_FILE = PROJECT_ROOT / "library/probes.yaml"


@dataclass(frozen=True)
class ProbeMove:
    utterance: str
    intent: str  # the class the probe is written for
    before: str | None  # the motion the act gets from the live library (None: it had no such act)
    before_class: str  # that act's class (the candidate's class is where it goes)


def load_probes(path: Path = PROBES_FILE) -> dict[str, tuple[str, ...]]:
    """intent -> its probe utterances; a malformed file is a ValueError of one line naming it."""
    raw = yaml.safe_load(Path(path).read_text(encoding="utf-8"))
    lists = isinstance(raw, dict) and all(isinstance(v, list) and v for v in raw.values())
    if not lists or not set(raw) <= set(CLASSES) or not all(
            isinstance(u, str) and u.strip() for v in raw.values() for u in v):
        raise ValueError(f"{path}: expected a mapping from classes ({', '.join(CLASSES)}) to lists of "
                         "non-empty utterances")
    return {cls: tuple(utterances) for cls, utterances in raw.items()}


def with_candidate(planner: LocalPlanner, entry: LibraryEntry) -> LocalPlanner:
    """A view of the planner whose variant choice also sees entry (same model; the library unchanged)."""
    evidence = (f"{entry.name.replace('_', ' ')}: {entry.description}", *entry.examples)
    trial = copy.copy(planner)
    trial._evidence = lambda: {**motion_evidence(planner.library), entry.name: (entry.cls, evidence)}
    trial.variants = VariantChooser(planner.variants.projections, planner.variants.describe,
                                    planner.variants.weights, planner.variants.annotated,
                                    planner.variants.read_classes)
    return trial


def probe_moves(planner: LocalPlanner, entry: LibraryEntry,
                probes: dict[str, tuple[str, ...]] | None = None) -> list[ProbeMove]:
    """Every probe act whose motion would become the candidate entry, with the motion it has now."""
    trial, moves = with_candidate(planner, entry), []
    for intent, utterances in (load_probes() if probes is None else probes).items():
        for utterance in utterances:
            _, now = planner.acts(utterance)
            _, then = trial.acts(utterance)
            for k, act in enumerate(then):
                if act.variant == entry.name:
                    old = now[k] if k < len(now) else None
                    before = (old.variant, old.cls) if old else (None, intent)
                    moves.append(ProbeMove(utterance, intent, *before))
    return moves
