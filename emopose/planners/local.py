"""planner=local: the embedded offline planner (no network): ordered plans from sentence embeddings.

1. Cut the utterance into candidate segments (planners/segment.py) and embed them with the utterance
   in one batch.
2. Classify each segment (and, with dialogue history, the utterance read after the previous turn); merge a segment into its predecessor when it predicts the same class, is too
   short to carry an act, or is not confident, so only clear changes of communicative act split a plan.
3. Per act: the variant is the class member whose library description is most similar to the act's
   text (descriptions come from the live library, so a new variant is selectable without retraining);
   intensity from cues (intensifiers and exclamations up, hedges down); trigger = the act's anchoring
   phrase (a class cue if one occurs, else its opening words); reply = the input text (narration mode).
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass

import numpy as np

from emopose import CLASSES
from emopose.library import MotionLibrary
from emopose.planners.base import PlannerOutput, PlanRequest, timed
from emopose.planners.keyword import KEYWORD_CUES
from emopose.planners.local_model import TrainingConfig, load_or_train
from emopose.planners.segment import Segment, segments

_UP = re.compile(r"\b(very|really|so|extremely|absolutely|totally|incredibly|truly|definitely|never|"
                 r"always|huge|amazing|terrible|must)\b", re.IGNORECASE)
_DOWN = re.compile(r"\b(maybe|perhaps|a bit|a little|slightly|kind of|sort of|somewhat|might|"
                   r"possibly|i guess|quietly|gently)\b", re.IGNORECASE)
_FILLER = {"well", "so", "and", "but", "oh", "ok", "okay", "um", "uh", "then", "now", "also"}
_WORDS = re.compile(r"[\w'-]+")


def intensity_from_cues(text: str) -> int:
    score = 3 + min(2, len(_UP.findall(text))) + min(1, text.count("!")) - min(2, len(_DOWN.findall(text)))
    letters = [c for c in text if c.isalpha()]
    if len(letters) >= 4 and sum(c.isupper() for c in letters) / len(letters) > 0.6:
        score += 1
    return int(min(5, max(1, score)))


def anchoring_phrase(text: str, cls: str) -> str:
    lowered = text.lower()
    for cue in sorted(KEYWORD_CUES.get(cls, ()), key=len, reverse=True):
        match = re.search(rf"(?<![\w']){re.escape(cue)}(?![\w'])", lowered)
        if match:
            return text[match.start():match.end()]
    words = list(_WORDS.finditer(text))
    while len(words) > 1 and words[0].group(0).lower() in _FILLER:
        words.pop(0)
    if not words:
        return text
    last = words[min(3, len(words)) - 1]
    return text[words[0].start():last.end()]


@dataclass
class _Act:
    parts: list[Segment]
    proba: np.ndarray
    vector: np.ndarray
    cls: str


class LocalPlanner:
    name = "local"

    def __init__(self, library: MotionLibrary, train_files: list[str], cache_dir: str = "~/.cache/emopose",
                 training: dict | None = None, min_words: int = 2, act_cost: float = -0.75,
                 max_span_segments: int = 4, max_records: int = 4, context_weight: float = 0.5,
                 temperature: float = 3.0) -> None:
        self.library = library
        self.train_files = list(train_files)
        self.model = load_or_train(list(train_files), cache_dir, TrainingConfig(**(training or {})))
        self.min_words, self.act_cost, self.max_records = min_words, act_cost, max_records
        self.max_span_segments = max_span_segments
        self.temperature = temperature
        self.context_weight = context_weight
        self._variant_vectors: tuple[int, dict[str, tuple[list[str], np.ndarray]]] = (-1, {})

    def plan(self, request: PlanRequest) -> PlannerOutput:
        with timed() as clock:
            acts = self.acts(request.utterance, request.history)
            gestures = [self._record(act, request.utterance) for act in acts]
            raw = json.dumps({"reply": request.utterance, "gestures": gestures})
        return PlannerOutput(raw=raw, latency_s=clock.elapsed)

    def acts(self, utterance: str, history: tuple[dict, ...] = ()) -> list[_Act]:
        """The best split of the utterance into acts: contiguous groups of candidate segments, each
        classified as a whole, maximising sum(log p(class | group)) - act_cost * groups, with
        neighbouring acts of different classes. One act wins unless the parts disagree confidently."""
        pieces = segments(utterance) or [Segment(utterance, 0, len(utterance), True)]
        n = len(pieces)
        spans = [(i, j) for i in range(n) for j in range(i + 1, n + 1)
                 if (j - i <= self.max_span_segments or (i, j) == (0, n)) and self._long_enough(pieces[i:j], n)]
        texts = [utterance[pieces[i].start:pieces[j - 1].end] for i, j in spans]
        if history:
            texts.append(f"{history[-1].get('content', '')} {utterance}")
        vectors, probas = self.model.encode_and_classify(texts)
        whole = spans.index((0, n))
        if history:
            probas[whole] = self._with_context(probas[whole], probas[-1])
        return self._best_split(pieces, spans, vectors, probas)[: self.max_records]

    def _long_enough(self, group: list[Segment], total: int) -> bool:
        return len(group) == total or sum(p.words for p in group) >= self.min_words

    def _best_split(self, pieces, spans, vectors, probas) -> list[_Act]:
        # The classifier is trained sharp; softening it lets confident parts outweigh a confident whole.
        log_p = np.log(np.maximum(probas, 1e-12)) / self.temperature
        log_p -= np.log(np.exp(log_p).sum(axis=1, keepdims=True))
        # best[j][c]: score of the best split of pieces[:j] whose last act has class c.
        best = np.full((len(pieces) + 1, len(CLASSES)), -np.inf)
        back: dict[tuple[int, int], tuple[int, int, int]] = {}
        best[0, :] = 0.0
        for k, (i, j) in enumerate(spans):
            for c in range(len(CLASSES)):
                before = best[i].copy()
                if i > 0:
                    before[c] = -np.inf  # neighbouring acts differ in class
                prev = int(np.argmax(before))
                score = before[prev] + log_p[k, c] - self.act_cost
                if score > best[j, c]:
                    best[j, c], back[(j, c)] = score, (i, prev, k)
        acts, j, c = [], len(pieces), int(np.argmax(best[len(pieces)]))
        while j > 0:
            i, prev, k = back[(j, c)]
            proba = probas[k].copy()
            acts.append(_Act(list(pieces[i:j]), proba, vectors[k], CLASSES[c]))
            j, c = i, prev
        return acts[::-1]

    def _with_context(self, own: np.ndarray, in_context: np.ndarray) -> np.ndarray:
        """Geometric mix of the utterance's own class distribution and that of the utterance read
        after the previous dialogue turn: elliptical replies ("That one.") borrow meaning from it."""
        mixed = own * in_context**self.context_weight
        return mixed / mixed.sum()

    def _record(self, act: _Act, utterance: str) -> dict:
        text = utterance[act.parts[0].start:act.parts[-1].end]
        return {"class": act.cls, "variant": self._variant(act.cls, act.vector),
                "intensity": intensity_from_cues(text), "trigger": anchoring_phrase(text, act.cls),
                "confidence": round(float(act.proba[CLASSES.index(act.cls)]), 3)}

    def _variant(self, cls: str, vector: np.ndarray) -> str | None:
        version, by_class = self._variant_vectors
        if version != self.library.version:
            entries = [e for e in self.library.snapshot.entries.values() if e.motion_type == "sequence"]
            matrix, _ = self.model.encode_and_classify(
                [f"{e.name.replace('_', ' ')}: {e.description}" for e in entries])
            by_class = {c: ([e.name for e in entries if e.cls == c],
                            matrix[[i for i, e in enumerate(entries) if e.cls == c]]) for c in CLASSES}
            self._variant_vectors = (self.library.version, by_class)
        names, matrix = by_class.get(cls, ([], None))
        if not names:
            return None
        return names[int(np.argmax(matrix @ vector))]
