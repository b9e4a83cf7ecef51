"""planner=local: the embedded offline planner (no network): ordered plans from one encoder pass.

1. Cut the utterance into candidate segments (planners/local/segment.py) and run the model once over the
   last dialogue turns and the utterance as one input (planners/local/model.py): an elliptical reply
   ("That one, with the feathers.") is read in context. A history the relevance head finds unrelated
   to the utterance is dropped and the utterance read alone (a second pass), so a change of topic
   plans as if the dialogue had just begun; unrelated histories precede training items too
   (planners/local/data.py), which keeps the classes steady where the head errs.
2. Choose the split into acts: the best split of a semi-Markov CRF over the segments (act class
   logits plus boundary logits at the chosen boundaries; neighbouring acts differ), trained as one.
3. Per act: the motion whose library description best fits the act's words and meaning, chosen with
   its class (planners/local/variants.py; descriptions come from the live library, so a new motion is
   selectable without retraining), and for a pointing act the direction its words name
   (planners/local/direction.py); intensity from cues (intensifiers and exclamations up, hedges down);
   trigger = the words the gesture belongs to (the contract's rule: its lexical affiliate, starting at the
   word the stroke lands on): from the word the onset head picks to the end of the phrase the anchor
   head marks (affiliate.trigger_span), a leading subject or joiner the clause rules find still trimmed
   (planners/local/affiliate.py); reply = the input text (it always narrates).

The model is trained by `+experiment=train_local`, or before first use when planner.train_if_missing
(LocalPlanner.from_config; progress bars on stderr), seeded and cached under cache_dir
(planners/local/artifact.py). The planner itself only loads it.
"""

from __future__ import annotations

import json
import logging
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from emopose import CLASSES
from emopose.library import MotionLibrary
from emopose.planners.base import PlannerOutput, PlanRequest, timed
from emopose.planners.local import semi_crf
from emopose.planners.local.affiliate import act_trigger
from emopose.planners.local.artifact import (
    cached_artifact,
    load_model,
    train_artifact,
    train_missing_artifact,
)
from emopose.planners.local.catalogue import motion_catalogue, motion_evidence
from emopose.planners.local.config import LocalSettings
from emopose.planners.local.direction import added_ways, off_way, pointing_motion
from emopose.planners.local.heads import Analysis
from emopose.planners.local.inference import LocalInference
from emopose.planners.local.segment import Segment, segments
from emopose.planners.local.threads import resolve_threads, torch_threads
from emopose.planners.local.variant_score import Features, Weights
from emopose.planners.local.variants import ClassMove, VariantChooser

_UP = re.compile(r"\b(very|really|so|extremely|absolutely|totally|incredibly|truly|definitely|never|"
                 r"always|huge|amazing|terrible|must)\b", re.IGNORECASE)
_DOWN = re.compile(r"\b(maybe|perhaps|a bit|a little|slightly|kind of|sort of|somewhat|might|"
                   r"possibly|i guess|quietly|gently)\b", re.IGNORECASE)
log = logging.getLogger(__name__)


def intensity_from_cues(text: str) -> int:
    score = 3 + min(2, len(_UP.findall(text))) + min(1, text.count("!")) - min(2, len(_DOWN.findall(text)))
    letters = [c for c in text if c.isalpha()]
    if len(letters) >= 4 and sum(c.isupper() for c in letters) / len(letters) > 0.6:
        score += 1
    return int(min(5, max(1, score)))


@dataclass
class ScoredUtterance:
    analysis: Analysis
    pieces: list[Segment]
    spans: list[tuple[int, int]]  # candidate acts: piece index ranges [i, j)
    logits: np.ndarray  # (spans, classes) unnormalised class scores
    features: Features  # one row per span: what the variant choice reads (planners/local/variants.py)
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
    """Built by from_config (conf/planner/local.yaml's _target_); __init__ only loads a trained artifact."""

    name = "local"
    sampled = False  # a seeded model: the same utterance always gets the same plan

    @classmethod
    def from_config(cls, library: MotionLibrary, *, train_if_missing: bool, **settings) -> LocalPlanner:
        """Check the settings (LocalSettings), then, when train_if_missing, train the artifact if none is
        cached (the first use on a fresh machine: minutes, progress bars on stderr), then load it. Torch
        gets the cores free at the start (planner.threads, planners/local/threads.py)."""
        checked = LocalSettings.model_validate(settings)
        threads = resolve_threads(checked.threads)
        if train_if_missing:
            with torch_threads(threads):
                train_missing_artifact(checked.train_files, checked.cache_dir, checked.training,
                                       motion_catalogue(library))
        return cls(library, checked, threads)

    def __init__(self, library: MotionLibrary, settings: LocalSettings, threads: int | None = None) -> None:
        """Load the cached artifact for the settings; none is an error naming the job that trains it.
        threads: torch's pool for inference (None: resolved from planner.threads now)."""
        import torch

        self.threads = resolve_threads(settings.threads) if threads is None else threads
        torch.set_num_threads(self.threads)
        self.library, self.settings = library, settings
        self.variant_weights = Weights(settings.variant_word_weight, settings.variant_shared_weight,
                                       settings.variant_pretrained_share)
        self.class_move = ClassMove(settings.variant_class_weight, settings.variant_class_weight_new)
        # the split parameters stay attributes: train_local's held-out sweep sets them in turn
        self.temperature, self.boundary_weight = settings.temperature, settings.boundary_weight
        self.act_cost = settings.act_cost
        self._load(cached_artifact(settings.train_files, settings.cache_dir, settings.training))

    def _load(self, artifact: Path) -> None:
        log.info("local planner: loading %s", artifact)
        settings = self.settings
        self.model = LocalInference(load_model(artifact, settings.training), settings.bf16_inference,
                                    settings.trace_inference)
        model = self.model.model
        self.variants = VariantChooser(model.variant_projections, self.model.describe, self.variant_weights,
                                       frozenset(model.annotated_motions), self.model.read_classes)

    def retrain(self) -> None:
        """Train again (replacing the cached artifact) and use the new model (train_local's job.retrain)."""
        settings = self.settings
        with torch_threads(self.threads):
            self._load(train_artifact(settings.train_files, settings.cache_dir, settings.training,
                                      self._catalogue()))

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
        return scored.analysis, self.best_split(scored)[: self.settings.max_records]

    def score(self, utterance: str, history: tuple[dict, ...] = ()) -> ScoredUtterance:
        """Everything the split needs from the model: one forward pass over the dialogue and the utterance
        (two when the history turns out not to bear on it: the utterance is then read alone)."""
        analysis = self.model.analyse([utterance], [history])[0]
        relevance = analysis.relevance_logit
        if relevance is not None and relevance < self.settings.history_threshold:
            analysis = self.model.analyse([utterance])[0]
        pieces = segments(utterance) or [Segment(utterance, 0, len(utterance), True)]
        n = len(pieces)
        spans = [(i, j) for i in range(n) for j in range(i + 1, n + 1)
                 if j - i == n or sum(p.words for p in pieces[i:j]) >= self.settings.min_words]
        logits, features = self.model.classify_spans(analysis, [(pieces[i].start, pieces[j - 1].end)
                                                                for i, j in spans])
        boundaries = self.model.boundary_logits(analysis, pieces)
        return ScoredUtterance(analysis, pieces, spans, logits, features, boundaries)

    def best_split(self, scored: ScoredUtterance) -> list[_Act]:
        """The semi-CRF's best split (planners/local/semi_crf.py): act scores are the class logits /
        temperature, an act starting inside the utterance adds boundary_weight * its boundary logit -
        act_cost. The model is trained with (1, 1, 0); the knobs are for the held-out sweep in
        train_local. Each act's motion is chosen with its class (planners/local/variants.py): a motion
        of another class that fits the act's words better than its own class's may move it
        (variant_class_weight, and variant_class_weight_new for a motion the training data never
        annotated); a pointing motion added by file only when the act names its way (direction.py)."""
        pieces, spans = scored.pieces, scored.spans
        openings = self.boundary_weight * scored.boundaries - self.act_cost
        split = semi_crf.best_split(len(pieces), spans, scored.logits / self.temperature, openings)
        acts: list[_Act] = []
        ways = added_ways(self._evidence(), self.settings.pointing_directions, self.settings.pointing_frame)
        for n, (k, c) in enumerate(split):
            proba = softmax(scored.logits[k])
            neighbours = {acts[-1].cls} if acts else set()  # neighbouring acts keep differing in class
            neighbours |= {CLASSES[split[n + 1][1]]} if n + 1 < len(split) else set()
            words = " ".join(piece.text for piece in pieces[spans[k][0]:spans[k][1]])
            cls, variant = self.variants.choose(self._evidence, self.library.version, CLASSES[c], proba,
                                                scored.features[k], self.class_move, frozenset(neighbours),
                                                off_way(words, ways, self.settings.pointing_frame))
            acts.append(_Act(pieces[spans[k][0]].start, pieces[spans[k][1] - 1].end, cls, proba, variant))
        return acts

    def _record(self, act: _Act, analysis: Analysis, utterance: str) -> dict:
        text = utterance[act.start:act.end]
        start, end = act_trigger(utterance, analysis, (act.start, act.end), act.cls)
        trigger, variant = utterance[start:end], act.variant
        directional = self.settings.pointing_directions.values()
        # a direction the words name decides among the directional motions (planners/local/direction.py);
        # a pointing motion outside them (one added by file) that fits the words best keeps its pick
        if act.cls == "pointing" and variant in directional:
            pointing = frozenset(n for n, (cls, _) in self._catalogue().items() if cls == "pointing")
            variant = pointing_motion((trigger, text), self.settings.pointing_directions, pointing,
                                      self.settings.pointing_frame) or variant
        return {"class": act.cls, "variant": variant, "intensity": intensity_from_cues(text),
                "trigger": trigger, "confidence": round(float(act.proba[CLASSES.index(act.cls)]), 3)}

    def _catalogue(self) -> dict[str, tuple[str, str]]:
        return motion_catalogue(self.library)

    def _evidence(self) -> dict[str, tuple[str, tuple[str, ...]]]:
        return motion_evidence(self.library)
