"""What the local planner's heads read: per-token states of one text, pooled over character spans.

- act head: class logits of any candidate act (a character span), from the normalised mean of its
  class states (one cumulative sum serves every span);
- boundary head: whether a new communicative act starts at a candidate segment boundary, from the
  states of the segments on either side; act and boundary logits are also the potentials of the
  semi-Markov CRF over segments (planners/semi_crf.py), which is how the planner splits;
- anchor head: per token, whether it belongs to the phrase that carries the act (the trigger);
- onset head: per token, how likely the act's trigger starts there (its affiliate's first word, where the
  stroke lands): a softmax over the act's tokens picks it, which a per-token inside/outside score cannot
  (the first words of a phrase are where that score is least sure);
- relevance head: whether the dialogue history read before the utterance bears on it, from the
  [CLS] state, which attends to both (BERT's sentence-pair head; a history that does not bear on the
  utterance is dropped: planners/local.py).

variant_features pools the same token ranges of the semantic and lexical states, and lists their
tokens, for the variant choice (planners/local/variant_score.py).
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass

import numpy as np

from emopose import CLASSES
from emopose.planners.local.segment import Segment
from emopose.planners.local.variant_score import Features

MAX_TOKENS = 128  # the encoder's input, dialogue prefix included


@dataclass
class Analysis:
    """One text after the forward pass: token character starts and per-token states (float32)."""

    starts: list[int]
    class_states: object  # torch (T, D), from the fine-tuned top layers
    semantic_states: object  # torch (T, D), from the pretrained top layers (sentence similarity)
    lexical_states: object  # torch (T, D), the word embeddings (which words)
    anchor_logits: np.ndarray  # (T,)
    onset_logits: np.ndarray  # (T,) compared within one act only
    relevance_logit: float | None = None  # whether the history bears on the text (None: read without one)
    token_ids: np.ndarray | None = None  # (T,); with word_weights, needed by variant_features only
    word_weights: object = None  # torch (T,), how distinctive each token is

    def token_range(self, start: int, end: int) -> tuple[int, int]:
        return token_range(self.starts, start, end)


def token_range(starts: list[int], start: int, end: int) -> tuple[int, int]:
    """Tokens (by character start) starting inside [start, end); never empty (a span cut off by
    truncation gets the last)."""
    first, last = bisect.bisect_left(starts, start), bisect.bisect_left(starts, end)
    if first >= last:
        first = min(first, len(starts) - 1)
        last = first + 1
    return first, last


def pooled(states, ranges: list[tuple[int, int]]):
    """Normalised mean of states over each token range, (len(ranges), D), via one cumulative sum."""
    import torch

    summed = torch.cat([states.new_zeros(1, states.shape[1]), states.cumsum(0)])
    first = torch.tensor([a for a, _ in ranges])
    last = torch.tensor([b for _, b in ranges])
    means = (summed[last] - summed[first]) / (last - first).unsqueeze(1).to(states.dtype)
    return torch.nn.functional.normalize(means, dim=-1)


def boundary_features(left, right):
    """(boundaries, 4D): [left, right, left*right, |left-right|] of the pooled segments either side."""
    import torch

    return torch.cat([left, right, left * right, (left - right).abs()], dim=1)


def new_heads(width: int) -> tuple:
    """(act head, boundary head, anchor head, relevance head, onset head), freshly initialised (seed
    first)."""
    import torch

    # created in this order: the seeded initialisation depends on it
    act = torch.nn.Linear(width, len(CLASSES))
    boundary = torch.nn.Sequential(torch.nn.Linear(4 * width, 64), torch.nn.ReLU(), torch.nn.Linear(64, 1))
    anchor = torch.nn.Linear(width, 1)
    relevance = torch.nn.Linear(width, 1)
    onset = torch.nn.Linear(width, 1)
    return act, boundary, anchor, relevance, onset


def span_scores(act_head, logit_scale: float, analysis: Analysis,
                spans: list[tuple[int, int]]) -> tuple[np.ndarray, Features]:
    """(class logits (S, 8), variant features) of character spans of the text. The logits are
    unnormalised: the split model compares them across spans, softmax gives class probabilities."""
    import torch

    ranges = [analysis.token_range(a, b) for a, b in spans]
    with torch.inference_mode():
        logits = act_head(pooled(analysis.class_states, ranges)) * logit_scale
        return logits.numpy(), variant_features(analysis, ranges)


def variant_features(analysis: Analysis, ranges: list[tuple[int, int]]) -> Features:
    """What the variant choice reads of each token range (planners/local/variant_score.py): the pooled
    semantic, lexical and distinctive (rarity-weighted word) vectors, and the tokens with their rarity."""
    import torch

    with torch.inference_mode():
        distinctive = analysis.lexical_states * analysis.word_weights.unsqueeze(1)
        vectors = [pooled(states, ranges).numpy()
                   for states in (analysis.semantic_states, analysis.lexical_states, distinctive)]
        weights = analysis.word_weights.numpy()
    return Features(*vectors, [(analysis.token_ids[a:b], weights[a:b]) for a, b in ranges])


def boundary_scores(boundary_head, analysis: Analysis, pieces: list[Segment]) -> np.ndarray:
    """Logit that a new act starts before pieces[k], for k = 1 .. len(pieces) - 1."""
    import torch

    if len(pieces) < 2:
        return np.zeros(0)
    with torch.inference_mode():
        means = pooled(analysis.class_states, [analysis.token_range(p.start, p.end) for p in pieces])
        return boundary_head(boundary_features(means[:-1], means[1:])).squeeze(-1).numpy()
