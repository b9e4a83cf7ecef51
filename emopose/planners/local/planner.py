"""planner=local: the embedded offline planner (no network): ordered plans from one encoder pass.

1. Cut the utterance into candidate segments (planners/segment.py) and run the model once over the
   last dialogue turns and the utterance as one input (planners/local_model.py): an elliptical reply
   ("That one, with the feathers.") is read in context. A history the relevance head finds unrelated
   to the utterance is dropped and the utterance read alone (a second pass), so a change of topic
   plans as if the dialogue had just begun; unrelated histories precede training items too
   (planners/local_data.py), which keeps the classes steady where the head errs.
2. Choose the split into acts: the best split of a semi-Markov CRF over the segments (act class
   logits plus boundary logits at the chosen boundaries; neighbouring acts differ), trained as one.
3. Per act: the motion whose library description best fits the act's words and meaning, chosen with
   its class (planners/local_variants.py; descriptions come from the live library, so a new motion is
   selectable without retraining); intensity from cues (intensifiers and exclamations up, hedges down);
   trigger = the words the anchor head marks around its strongest token; reply = the input text
   (narration mode).

The model is trained by `+experiment=train_local` or at first use (progress bars on stderr), seeded and
cached under cache_dir (planners/local_artifact.py).
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass

import numpy as np

from emopose import CLASSES
from emopose.library import MotionLibrary
from emopose.planners.base import PlannerOutput, PlanRequest, timed
from emopose.planners.local import semi_crf
from emopose.planners.local.artifact import load_model, train_artifact
from emopose.planners.local.config import TrainingConfig
from emopose.planners.local.heads import Analysis
from emopose.planners.local.inference import LocalInference
from emopose.planners.local.segment import Segment, segments
from emopose.planners.local.variants import ClassMove, Features, VariantChooser, Weights

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
    features: Features  # one row per span: what the variant choice reads (planners/local_variants.py)
    boundaries: np.ndarray  # (pieces - 1,) logit that a new act starts before pieces[k + 1]


@dataclass
class _Act:
    start: int
    end: int
    cls: str
    proba: np.ndarray
    variant: str | None


def softmax(logits: np.ndarray) -> np.ndarray:
    shifted = np.exp(logits - logits.max(axis=-1, keepdims=True))
    return shifted / shifted.sum(axis=-1, keepdims=True)


class LocalPlanner:
    name = "local"

    def __init__(self, library: MotionLibrary, train_files: list[str], cache_dir: str, training: dict,
                 min_words: int, temperature: float, boundary_weight: float, act_cost: float, max_records: int,
                 variant_word_weight: float, variant_shared_weight: float, variant_pretrained_share: float,
                 variant_class_weight: float, variant_class_weight_new: float, history_threshold: float,
                 bf16_inference: bool, trace_inference: bool) -> None:
        if not temperature > 0:
            raise ValueError(f"planner.temperature must be positive, got {temperature!r}")
        for name, weight in (("variant_word_weight", variant_word_weight),
                             ("variant_shared_weight", variant_shared_weight),
                             ("variant_class_weight", variant_class_weight),
                             ("variant_class_weight_new", variant_class_weight_new)):
            if not isinstance(weight, int | float) or not 0 <= weight < math.inf:
                raise ValueError(f"planner.{name} must be a finite number >= 0 (0: no weight), "
                                 f"got {weight!r}")
        if not isinstance(variant_pretrained_share, int | float) or not 0 <= variant_pretrained_share <= 1:
            raise ValueError(f"planner.variant_pretrained_share must be a number from 0 to 1, "
                             f"got {variant_pretrained_share!r}")
        if not isinstance(history_threshold, int | float) or history_threshold != history_threshold:
            raise ValueError(f"planner.history_threshold must be a number (-.inf keeps every history), "
                             f"got {history_threshold!r}")
        self.library = library
        self.train_files = list(train_files)
        self.cache_dir, self.config = cache_dir, TrainingConfig.model_validate(training)
        self.bf16_inference, self.trace_inference = bf16_inference, trace_inference
        self.variant_weights = Weights(variant_word_weight, variant_shared_weight, variant_pretrained_share)
        self.class_move = ClassMove(variant_class_weight, variant_class_weight_new)
        self.min_words, self.max_records = min_words, max_records
        self.history_threshold = history_threshold
        self.temperature, self.boundary_weight, self.act_cost = temperature, boundary_weight, act_cost
        self._load(retrain=False)  # first use trains: the train_local job's own call

    def _load(self, retrain: bool) -> None:
        artifact = train_artifact(self.train_files, self.cache_dir, self.config, self._catalogue(), retrain)
        self.model = LocalInference(load_model(artifact, self.config), self.bf16_inference, self.trace_inference)
        model = self.model.model
        self.variants = VariantChooser(model.variant_projections, self.model.describe, self.variant_weights,
                                       frozenset(model.annotated_motions))

    def retrain(self) -> None:
        """Train again (replacing the cached artifact) and use the new model."""
        self._load(retrain=True)

    def plan(self, request: PlanRequest) -> PlannerOutput:
        with timed() as clock:
            analysis, acts = self.acts(request.utterance, request.history)
            gestures = [self._record(act, analysis, request.utterance) for act in acts]
            raw = json.dumps({"reply": request.utterance, "gestures": gestures})
        return PlannerOutput(raw=raw, latency_s=clock.elapsed)

    def acts(self, utterance: str, history: tuple[dict, ...] = ()) -> tuple[Analysis | None, list[_Act]]:
        """The best split of the utterance into acts (see best_split), at most max_records of them.
        A blank utterance (or one of characters the tokenizer drops, such as a zero-width space) has no
        acts and nothing to analyse."""
        if not self.model.readable(utterance):
            return None, []
        scored = self.score(utterance, history)
        return scored.analysis, self.best_split(scored)[: self.max_records]

    def score(self, utterance: str, history: tuple[dict, ...] = ()) -> ScoredUtterance:
        """Everything the split needs from the model: one forward pass over the dialogue and the utterance
        (two when the history turns out not to bear on it: the utterance is then read alone)."""
        analysis = self.model.analyse([utterance], [history])[0]
        if analysis.relevance_logit is not None and analysis.relevance_logit < self.history_threshold:
            analysis = self.model.analyse([utterance])[0]
        pieces = segments(utterance) or [Segment(utterance, 0, len(utterance), True)]
        n = len(pieces)
        spans = [(i, j) for i in range(n) for j in range(i + 1, n + 1)
                 if j - i == n or sum(p.words for p in pieces[i:j]) >= self.min_words]
        logits, features = self.model.classify_spans(analysis, [(pieces[i].start, pieces[j - 1].end)
                                                                for i, j in spans])
        boundaries = self.model.boundary_logits(analysis, pieces)
        return ScoredUtterance(analysis, pieces, spans, logits, features, boundaries)

    def best_split(self, scored: ScoredUtterance) -> list[_Act]:
        """The semi-CRF's best split (planners/semi_crf.py): act scores are the class logits / temperature,
        an act starting inside the utterance adds boundary_weight * its boundary logit - act_cost.
        The model is trained with (1, 1, 0); the knobs are for the held-out sweep in train_local.
        Each act's motion is chosen with its class (planners/local_variants.py): a motion of another class
        that fits the act's words better than its own class's may move it (variant_class_weight, and
        variant_class_weight_new for a motion the training data never annotated)."""
        pieces, spans = scored.pieces, scored.spans
        openings = self.boundary_weight * scored.boundaries - self.act_cost
        split = semi_crf.best_split(len(pieces), spans, scored.logits / self.temperature, openings)
        acts: list[_Act] = []
        for n, (k, c) in enumerate(split):
            proba = softmax(scored.logits[k])
            neighbours = {acts[-1].cls} if acts else set()  # neighbouring acts keep differing in class
            neighbours |= {CLASSES[split[n + 1][1]]} if n + 1 < len(split) else set()
            cls, variant = self.variants.choose(self._catalogue, self.library.version, CLASSES[c], proba,
                                                scored.features[k], self.class_move,
                                                frozenset(neighbours))
            acts.append(_Act(pieces[spans[k][0]].start, pieces[spans[k][1] - 1].end, cls, proba, variant))
        return acts

    def _record(self, act: _Act, analysis: Analysis, utterance: str) -> dict:
        text = utterance[act.start:act.end]
        start, end = trigger_span(utterance, analysis, (act.start, act.end))
        return {"class": act.cls, "variant": act.variant,
                "intensity": intensity_from_cues(text), "trigger": utterance[start:end],
                "confidence": round(float(act.proba[CLASSES.index(act.cls)]), 3)}

    def _catalogue(self) -> dict[str, tuple[str, str]]:
        """Selectable motions of the live library: name -> (class, text its description is matched by)."""
        return {e.name: (e.cls, f"{e.name.replace('_', ' ')}: {e.description}")
                for e in self.library.snapshot.entries.values() if e.motion_type == "sequence"}
