"""planner=local: the embedded offline planner (no network): ordered plans from sentence embeddings.

1. Cut the utterance into candidate segments (planners/segment.py) and run the model once over the
   utterance (and, with dialogue history, once more over the utterance read after the previous turn).
2. Choose the split into acts: the best split of a semi-Markov CRF over the segments (act class
   logits plus boundary logits at the chosen boundaries; neighbouring acts differ), trained as one.
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
from emopose.planners import semi_crf
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
    logits: np.ndarray  # (spans, classes) unnormalised class scores
    vectors: np.ndarray  # (spans, D) semantic vectors, for the variant choice
    boundaries: np.ndarray  # (pieces - 1,) logit that a new act starts before pieces[k + 1]


@dataclass
class _Act:
    start: int
    end: int
    cls: str
    proba: np.ndarray
    vector: np.ndarray


def softmax(logits: np.ndarray) -> np.ndarray:
    shifted = np.exp(logits - logits.max(axis=-1, keepdims=True))
    return shifted / shifted.sum(axis=-1, keepdims=True)


class LocalPlanner:
    name = "local"

    def __init__(self, library: MotionLibrary, train_files: list[str], cache_dir: str = "~/.cache/emopose",
                 training: dict | None = None, min_words: int = 2, temperature: float = 1.0,
                 boundary_weight: float = 1.0, act_cost: float = 0.0, max_records: int = 4,
                 context_weight: float = 0.5, bf16_inference: bool = True, trace_inference: bool = True) -> None:
        if not temperature > 0:
            raise ValueError(f"planner.temperature must be positive, got {temperature!r}")
        self.library = library
        self.train_files = list(train_files)
        self.model = self._build_model(cache_dir, training or {}, bf16_inference, trace_inference)
        self.min_words, self.max_records = min_words, max_records
        self.temperature, self.boundary_weight, self.act_cost = temperature, boundary_weight, act_cost
        self.context_weight = context_weight
        self._variant_vectors: tuple[int, dict[str, tuple[list[str], np.ndarray]]] = (-1, {})

    def _build_model(self, cache_dir: str, training: dict, bf16_inference: bool, trace_inference: bool):
        """The trained model (trained first if no cached one matches); planners/local_context.py swaps it."""
        return load_or_train(self.train_files, cache_dir, TrainingConfig(**training), bf16_inference,
                             trace_inference, self._catalogue())

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
        logits, vectors = self.model.classify_spans(analyses[0], [(pieces[i].start, pieces[j - 1].end)
                                                                  for i, j in spans])
        if history:
            whole = spans.index((0, n))
            in_context, _ = self.model.classify_spans(analyses[1], [(0, len(previous) + len(utterance))])
            logits[whole] = self._with_context(logits[whole], in_context[0])
        boundaries = self.model.boundary_logits(analyses[0], pieces)
        return ScoredUtterance(analyses[0], pieces, spans, logits, vectors, boundaries)

    def best_split(self, scored: ScoredUtterance) -> list[_Act]:
        """The semi-CRF's best split (planners/semi_crf.py): act scores are the class logits / temperature,
        an act starting inside the utterance adds boundary_weight * its boundary logit - act_cost.
        The model is trained with (1, 1, 0); the knobs are for the held-out sweep in train_local."""
        pieces, spans = scored.pieces, scored.spans
        openings = self.boundary_weight * scored.boundaries - self.act_cost
        split = semi_crf.best_split(len(pieces), spans, scored.logits / self.temperature, openings)
        return [_Act(pieces[spans[k][0]].start, pieces[spans[k][1] - 1].end, CLASSES[c],
                     softmax(scored.logits[k]), scored.vectors[k]) for k, c in split]

    def _with_context(self, own: np.ndarray, in_context: np.ndarray) -> np.ndarray:
        """The utterance's own class logits plus context_weight times the log-probabilities of the
        utterance read after the previous dialogue turn: elliptical replies ("That one.") borrow meaning."""
        return own + self.context_weight * np.log(softmax(in_context))

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
            matrix = self._describe([text for _, text in catalogue.values()])
            names = list(catalogue)
            by_class = {c: ([n for n in names if catalogue[n][0] == c],
                            matrix[[i for i, n in enumerate(names) if catalogue[n][0] == c]]) for c in CLASSES}
            self._variant_vectors = (self.library.version, by_class)
        names, matrix = by_class.get(cls, ([], None))
        if not names:
            return None
        return names[int(np.argmax(matrix @ self.model.project(vector[None])[0]))]

    def _describe(self, texts: list[str]) -> np.ndarray:
        """Description vectors in the space variant() compares projected act vectors in."""
        return self.model.embed(texts)
