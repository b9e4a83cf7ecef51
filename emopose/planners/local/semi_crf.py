"""A semi-Markov CRF over candidate segments: how the local planner scores a split into acts.

An utterance has n candidate segments (planners/segment.py). A split groups them into acts, contiguous
ranges [i, j) of segments, each with a class; neighbouring acts differ in class. Its score is

    sum over acts of span_scores[span, class] + sum over acts starting at i > 0 of openings[i - 1]

where `spans` lists the allowed ranges, span_scores holds one row of class scores per span and
openings[i - 1] scores an act starting at segment i. Training maximises the log-likelihood of the
annotated split against every split (log_partition: the forward algorithm, torch); planning takes the
best split (best_split: Viterbi, numpy). Both run in O(spans * classes^2).
"""

from __future__ import annotations

import numpy as np

Span = tuple[int, int]


def log_partition(n: int, spans: list[Span], span_scores, openings):
    """log of the sum of exp(score) over every split of n segments into allowed spans (torch, differentiable).
    Every segment end must be reachable (spans include all single segments)."""
    import torch

    classes = span_scores.shape[1]
    differ = torch.zeros(classes, classes)
    differ.fill_diagonal_(float("-inf"))  # row c: the previous act's class may be anything but c
    # entering[i]: log-sum over splits of segments[:i], as a new act of class c opens at segment i.
    entering: dict[int, object] = {0: torch.zeros(classes)}
    by_end: dict[int, list[int]] = {}
    for k, (_, j) in enumerate(spans):
        by_end.setdefault(j, []).append(k)
    alpha = None
    for j in range(1, n + 1):
        alpha = torch.logsumexp(torch.stack([entering[spans[k][0]] + span_scores[k] for k in by_end[j]]),
                                dim=0)
        if j < n:
            entering[j] = torch.logsumexp(alpha.unsqueeze(0) + differ, dim=1) + openings[j - 1]
    return torch.logsumexp(alpha, dim=0)


def split_score(acts: list[tuple[int, int]], spans: list[Span], span_scores, openings):
    """Score of one split, given as (span index, class index) per act in order (torch or numpy)."""
    total = 0.0
    for k, c in acts:
        i = spans[k][0]
        total = total + span_scores[k, c] + (openings[i - 1] if i else 0.0)
    return total


def best_split(n: int, spans: list[Span], span_scores: np.ndarray,
               openings: np.ndarray) -> list[tuple[int, int]]:
    """The highest-scoring split as (span index, class index) per act, in order."""
    classes = span_scores.shape[1]
    # best[j][c]: score of the best split of segments[:j] whose last act has class c.
    best = np.full((n + 1, classes), -np.inf)
    best[0, :] = 0.0
    back: dict[tuple[int, int], tuple[int, int, int]] = {}
    for k in sorted(range(len(spans)), key=lambda k: spans[k][1]):
        i, j = spans[k]
        opening = openings[i - 1] if i else 0.0
        for c in range(classes):
            before = best[i].copy()
            if i:
                before[c] = -np.inf
            prev = int(np.argmax(before))
            score = before[prev] + span_scores[k, c] + opening
            if score > best[j, c]:
                best[j, c], back[(j, c)] = score, (i, prev, k)
    out, j, c = [], n, int(np.argmax(best[n]))
    while j > 0:
        i, prev, k = back[(j, c)]
        out.append((k, c))
        j, c = i, prev
    return out[::-1]
