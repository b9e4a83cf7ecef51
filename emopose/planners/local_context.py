"""planner=local_context: the local planner that reads the dialogue with the utterance (opt-in).

The same plan as planner=local (planners/local.py: candidate segments, semi-CRF split, cue intensity,
anchor-head triggers) from a different model (planners/local_context_model.py):

- one forward pass over the last dialogue turns and the utterance as one input with role markers,
  trained on the dialogue split experiments/train/context/ as well (an elliptical "That one, with the
  feathers." is read in context; unrelated histories before single- and multi-act training items teach
  it that a history which does not bear on the utterance sways neither its classes nor its split);
- the variant is the class member whose projected description is nearest the act's projected vector
  in the pretrained sentence space (descriptions come from the live library, so a new variant is
  selectable without retraining; the projection is trained with motions left out per batch);
- top layers fine-tuned over cached frozen-layer states, bfloat16 where the CPU has it, progress bars:
  trained by `+experiment=train_local planner=local_context` or at first use (planners/local_artifact.py).
"""

from __future__ import annotations

import numpy as np

from emopose.library import MotionLibrary
from emopose.planners.local import LocalPlanner, ScoredUtterance
from emopose.planners.local_artifact import load_model, train_artifact
from emopose.planners.local_config import TrainingConfig
from emopose.planners.local_inference import LocalInference
from emopose.planners.segment import Segment, segments


class LocalContextPlanner(LocalPlanner):
    name = "local_context"

    def __init__(self, library: MotionLibrary, train_files: list[str], cache_dir: str = "~/.cache/emopose",
                 training: dict | None = None, min_words: int = 2, temperature: float = 1.0,
                 boundary_weight: float = 1.0, act_cost: float = 0.0, max_records: int = 4,
                 bf16_inference: bool = True, trace_inference: bool = True) -> None:
        # The history is read by the encoder itself, so planner=local's logit mix (context_weight) is off.
        super().__init__(library, train_files, cache_dir, training, min_words, temperature, boundary_weight,
                         act_cost, max_records, 0.0, bf16_inference, trace_inference)

    def _build_model(self, cache_dir: str, training: dict, bf16_inference: bool,
                     trace_inference: bool) -> LocalInference:
        self.cache_dir, self.config = cache_dir, TrainingConfig.model_validate(training)
        self.bf16_inference, self.trace_inference = bf16_inference, trace_inference
        return self._load(retrain=False)  # first use trains: the train_local job's own call

    def _load(self, retrain: bool) -> LocalInference:
        artifact = train_artifact(self.train_files, self.cache_dir, self.config, self._catalogue(), retrain)
        return LocalInference(load_model(artifact, self.config), self.bf16_inference, self.trace_inference)

    def retrain(self) -> None:
        """Train again (replacing the cached artifact) and use the new model."""
        self.model = self._load(retrain=True)
        self._variant_vectors = (-1, {})

    def score(self, utterance: str, history: tuple[dict, ...] = ()) -> ScoredUtterance:
        """Everything the split needs from the model: one forward pass over the dialogue and the
        utterance. Unrelated histories before single- and multi-act items are part of training
        (planners/local_data.py), so the split is read in context too."""
        return self._scored(utterance, self.model.analyse([utterance], [history])[0])

    def _scored(self, utterance: str, analysis) -> ScoredUtterance:
        pieces = segments(utterance) or [Segment(utterance, 0, len(utterance), True)]
        n = len(pieces)
        spans = [(i, j) for i in range(n) for j in range(i + 1, n + 1)
                 if j - i == n or sum(p.words for p in pieces[i:j]) >= self.min_words]
        logits, vectors = self.model.classify_spans(analysis, [(pieces[i].start, pieces[j - 1].end)
                                                               for i, j in spans])
        boundaries = self.model.boundary_logits(analysis, pieces)
        return ScoredUtterance(analysis, pieces, spans, logits, vectors, boundaries)

    def _describe(self, texts: list[str]) -> np.ndarray:
        """Descriptions go through the same projection as the acts (one space, so new motions compete)."""
        return self.model.project(self.model.embed(texts))
