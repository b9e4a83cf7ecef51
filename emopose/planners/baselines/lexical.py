"""Shared pieces of the single-label baselines: class descriptions, a tokenizer, contract output.

The TF-IDF and Jaccard baselines compare an utterance with one written description per class
(prompts/class_descriptions.yaml). Single-label planners answer with exactly one record whose class is
the best-scoring one, in the same contract JSON as every other planner.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import yaml

from emopose import CLASSES
from emopose.contract import GestureRecord
from emopose.planners.base import PlannerOutput, PlanRequest

_WORD = re.compile(r"[a-z0-9]+(?:'[a-z]+)?")
# Function words only. Words that carry class signal stay out of this list: negations, yes/no,
# deixis (this, there, here, over, up, down) and intensifiers (very).
STOP_WORDS = frozenset([
    "a", "an", "the", "and", "or", "but", "of", "to", "in", "on", "at", "for", "with", "by",
    "from", "as", "is", "are", "was", "were", "be", "been", "being", "it", "its", "that", "i",
    "you", "he", "she", "we", "they", "me", "him", "her", "us", "them", "my", "your", "our",
    "their", "what", "which", "who", "whom", "so", "than", "then", "too", "also", "just", "can",
    "could", "would", "should", "will", "shall", "may", "might", "do", "does", "did", "have",
    "has", "had", "such", "into", "about", "out", "off", "again",
])


def tokenize(text: str, drop_stop_words: bool = False) -> list[str]:
    """Lowercase word tokens (apostrophes kept inside words: don't, it's)."""
    tokens = _WORD.findall(text.lower().replace("\u2019", "'"))
    return [t for t in tokens if t not in STOP_WORDS] if drop_stop_words else tokens


def load_class_descriptions(path: str | Path) -> dict[str, str]:
    """{class: description} for all eight classes, in CLASSES order; errors name the file and class."""
    path = Path(path)
    try:
        raw = yaml.safe_load(path.read_text())
    except (OSError, yaml.YAMLError) as exc:
        raise ValueError(f"{path}: cannot read class descriptions ({exc})") from exc
    if not isinstance(raw, dict):
        raise ValueError(f"{path}: expected a mapping class -> description")  # noqa: TRY004 - a config error
    unknown = sorted(set(raw) - set(CLASSES))
    missing = [c for c in CLASSES if not isinstance(raw.get(c), str) or not raw[c].strip()]
    if unknown or missing:
        raise ValueError(f"{path}: unknown classes {unknown}, missing or empty descriptions {missing}; "
                         f"need one non-empty text for each of {list(CLASSES)}")
    return {c: raw[c].strip() for c in CLASSES}


def best_class(scores: np.ndarray) -> tuple[str, float]:
    """argmax over classes (ties go to the earlier class); all-zero scores mean no evidence: neutral."""
    if not np.any(scores > 0):
        return "neutral", 0.0
    k = int(np.argmax(scores))
    return CLASSES[k], float(scores[k])


def single_record_output(request: PlanRequest, cls: str, confidence: float, latency_s: float,
                         meta: dict | None = None) -> PlannerOutput:
    """Contract JSON with one record; the reply is the input text (narration mode, as keyword does)."""
    record = GestureRecord(cls=cls, confidence=min(1.0, max(0.0, confidence)))
    raw = json.dumps({"reply": request.utterance, "gestures": [record.as_json()]})
    return PlannerOutput(raw=raw, latency_s=latency_s, meta=meta or {})
