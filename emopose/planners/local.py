"""planner=local: the embedded offline planner (no network): ordered plans from sentence embeddings.

1. Cut the utterance into candidate segments (planners/segment.py) and run the model once over the
   utterance (and, with dialogue history, once more over the utterance read after the previous turn).
2. Choose the split into acts: contiguous groups of segments maximising the acts' class log
   probabilities plus the boundary head's logits at the chosen boundaries (neighbouring acts differ).
3. Per act: the variant is the class member whose library description is most similar to the act's
   text (descriptions come from the live library, so a new variant is selectable without retraining);
   intensity from cues (intensifiers and exclamations up, hedges down); trigger = the words the anchor
   head marks around its strongest token; reply = the input text (narration mode).
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass

import numpy as np

from emopose import CLASSES
from emopose.library import MotionLibrary
from emopose.planners.base import PlannerOutput, PlanRequest, timed
from emopose.planners.local_model import Analysis, TrainingConfig, load_or_train
from emopose.planners.segment import Segment, segments

_UP = re.compile(r"\b(very|really|so|extremely|absolutely|totally|incredibly|truly|definitely|never|"
                 r"always|huge|amazing|terrible|must)\b", re.IGNORECASE)
_DOWN = re.compile(r"\b(maybe|perhaps|a bit|a little|slightly|kind of|sort of|somewhat|might|"
                   r"possibly|i guess|quietly|gently)\b", re.IGNORECASE)
_WORDS = re.compile(r"[\w'-]+")


def intensity_from_cues(text: str) -> int:
    score = 3 + min(2, len(_UP.findall(text))) + min(1, text.count("!")) - min(2, len(_DOWN.findall(text)))
    letters = [c for c in text if c.isalpha()]
    if len(letters) >= 4 and sum(c.isupper() for c in letters) / len(letters) > 0.6:
        score += 1
    return int(min(5, max(1, score)))


def trigger_span(text: str, analysis: Analysis, act: tuple[int, int], max_words: int = 6) -> tuple[int, int]:
    """Character span of the act's anchoring phrase: the words around the token the anchor head rates
    highest, extended over neighbouring tokens it rates positive, at most max_words words."""
    first, last = analysis.token_range(*act)
    peak = first + int(np.argmax(analysis.anchor_logits[first:last]))
    lo = hi = peak
    while lo > first and analysis.anchor_logits[lo - 1] > 0:
        lo -= 1
    while hi + 1 < last and analysis.anchor_logits[hi + 1] > 0:
        hi += 1
    words = list(_WORDS.finditer(text, act[0], act[1]))
    if not words:
        return act
    # The peak may be a punctuation token: its word is the last one starting at or before it.
    centre = max((k for k, m in enumerate(words) if m.start() <= analysis.starts[peak]), default=0)
    marked = [k for k, m in enumerate(words) if m.end() > analysis.starts[lo] and m.start() <= analysis.starts[hi]]
    lo_word = max(min(marked, default=centre), centre - max_words + 1)
    hi_word = min(max(marked, default=centre), lo_word + max_words - 1)
    return words[lo_word].start(), words[hi_word].end()


@dataclass
class ScoredUtterance:
    analysis: Analysis
    pieces: list[Segment]
    spans: list[tuple[int, int]]  # candidate acts: piece index ranges [i, j)
    probas: np.ndarray  # (spans, classes)
    vectors: np.ndarray  # (spans, D) semantic vectors, for the variant choice
    boundaries: np.ndarray  # (pieces - 1,) logit that a new act starts before pieces[k + 1]


@dataclass
class _Act:
    start: int
    end: int
    cls: str
    proba: np.ndarray
    vector: np.ndarray


class LocalPlanner:
    name = "local"

    def __init__(self, library: MotionLibrary, train_files: list[str], cache_dir: str = "~/.cache/emopose",
                 training: dict | None = None, min_words: int = 2, temperature: float = 3.0,
                 boundary_weight: float = 0.5, act_cost: float = -1.0, max_records: int = 4,
                 context_weight: float = 0.5, bf16_inference: bool = True, trace_inference: bool = True) -> None:
        self.library = library
        self.train_files = list(train_files)
        self.model = load_or_train(list(train_files), cache_dir, TrainingConfig(**(training or {})), bf16_inference,
                                   trace_inference, self._catalogue())
        self.min_words, self.max_records = min_words, max_records
        self.temperature, self.boundary_weight, self.act_cost = temperature, boundary_weight, act_cost
        self.context_weight = context_weight
        self._variant_vectors: tuple[int, dict[str, tuple[list[str], np.ndarray]]] = (-1, {})

    def plan(self, request: PlanRequest) -> PlannerOutput:
        with timed() as clock:
            analysis, acts = self.acts(request.utterance, request.history)
            gestures = [self._record(act, analysis, request.utterance) for act in acts]
            raw = json.dumps({"reply": request.utterance, "gestures": gestures})
        return PlannerOutput(raw=raw, latency_s=clock.elapsed)

    def acts(self, utterance: str, history: tuple[dict, ...] = ()) -> tuple[Analysis | None, list[_Act]]:
        """The best split of the utterance into acts (see best_split), at most max_records of them.
        A blank utterance has no acts (and nothing to analyse)."""
        if not utterance.strip():
            return None, []
        scored = self.score(utterance, history)
        return scored.analysis, self.best_split(scored)[: self.max_records]

    def score(self, utterance: str, history: tuple[dict, ...] = ()) -> ScoredUtterance:
        """Everything the split needs from the model: one forward pass (two with history)."""
        pieces = segments(utterance) or [Segment(utterance, 0, len(utterance), True)]
        n = len(pieces)
        previous = f"{history[-1].get('content', '')} " if history else ""
        analyses = self.model.analyse([utterance] + ([previous + utterance] if history else []))
        spans = [(i, j) for i in range(n) for j in range(i + 1, n + 1)
                 if j - i == n or sum(p.words for p in pieces[i:j]) >= self.min_words]
        probas, vectors = self.model.classify_spans(analyses[0], [(pieces[i].start, pieces[j - 1].end)
                                                                  for i, j in spans])
        if history:
            whole = spans.index((0, n))
            in_context, _ = self.model.classify_spans(analyses[1], [(0, len(previous) + len(utterance))])
            probas[whole] = self._with_context(probas[whole], in_context[0])
        boundaries = self.model.boundary_logits(analyses[0], pieces)
        return ScoredUtterance(analyses[0], pieces, spans, probas, vectors, boundaries)

    def best_split(self, scored: ScoredUtterance) -> list[_Act]:
        """Maximise sum over acts of log p(class | act) / temperature (renormalised) plus, per chosen
        boundary, boundary_weight * its logit - act_cost; neighbouring acts have different classes."""
        pieces, spans, probas, vectors = scored.pieces, scored.spans, scored.probas, scored.vectors
        log_p = np.log(np.maximum(probas, 1e-12)) / self.temperature
        log_p -= np.log(np.exp(log_p).sum(axis=1, keepdims=True))
        # best[j][c]: score of the best split of pieces[:j] whose last act has class c.
        best = np.full((len(pieces) + 1, len(CLASSES)), -np.inf)
        back: dict[tuple[int, int], tuple[int, int, int]] = {}
        best[0, :] = 0.0
        for k, (i, j) in enumerate(spans):
            opening = self.boundary_weight * scored.boundaries[i - 1] - self.act_cost if i else 0.0
            for c in range(len(CLASSES)):
                before = best[i].copy()
                if i > 0:
                    before[c] = -np.inf  # neighbouring acts differ in class
                prev = int(np.argmax(before))
                score = before[prev] + log_p[k, c] + opening
                if score > best[j, c]:
                    best[j, c], back[(j, c)] = score, (i, prev, k)
        acts, j, c = [], len(pieces), int(np.argmax(best[len(pieces)]))
        while j > 0:
            i, prev, k = back[(j, c)]
            acts.append(_Act(pieces[i].start, pieces[j - 1].end, CLASSES[c], probas[k], vectors[k]))
            j, c = i, prev
        return acts[::-1]

    def _with_context(self, own: np.ndarray, in_context: np.ndarray) -> np.ndarray:
        """Geometric mix of the utterance's own class distribution and that of the utterance read
        after the previous dialogue turn: elliptical replies ("That one.") borrow meaning from it."""
        mixed = own * in_context**self.context_weight
        return mixed / mixed.sum()

    def _record(self, act: _Act, analysis: Analysis, utterance: str) -> dict:
        text = utterance[act.start:act.end]
        start, end = trigger_span(utterance, analysis, (act.start, act.end))
        return {"class": act.cls, "variant": self.variant(act.cls, act.vector),
                "intensity": intensity_from_cues(text), "trigger": utterance[start:end],
                "confidence": round(float(act.proba[CLASSES.index(act.cls)]), 3)}

    def _catalogue(self) -> dict[str, tuple[str, str]]:
        """Selectable motions of the live library: name -> (class, text its description is matched by)."""
        return {e.name: (e.cls, f"{e.name.replace('_', ' ')}: {e.description}")
                for e in self.library.snapshot.entries.values() if e.motion_type == "sequence"}

    def variant(self, cls: str, vector: np.ndarray) -> str | None:
        """The class member whose description is nearest the act's projected semantic vector."""
        version, by_class = self._variant_vectors
        if version != self.library.version:
            catalogue = self._catalogue()
            matrix = self.model.embed([text for _, text in catalogue.values()])
            names = list(catalogue)
            by_class = {c: ([n for n in names if catalogue[n][0] == c],
                            matrix[[i for i, n in enumerate(names) if catalogue[n][0] == c]]) for c in CLASSES}
            self._variant_vectors = (self.library.version, by_class)
        names, matrix = by_class.get(cls, ([], None))
        if not names:
            return None
        return names[int(np.argmax(matrix @ self.model.project(vector[None])[0]))]
