"""The semi-CRF's forward algorithm and Viterbi against brute-force enumeration of every split."""

import numpy as np
import pytest
import torch

from emopose.planners.local.data import multi_act, single_act
from emopose.planners.local.semi_crf import best_split, log_partition, split_score


def every_split(n: int, spans: list[tuple[int, int]], classes: int):
    """All splits of n segments into allowed spans, neighbouring classes distinct, as (span, class) lists."""
    index = {span: k for k, span in enumerate(spans)}

    def from_segment(i: int, previous: int | None):
        if i == n:
            yield []
            return
        for j in range(i + 1, n + 1):
            if (i, j) not in index:
                continue
            for c in range(classes):
                if c != previous:
                    for rest in from_segment(j, c):
                        yield [(index[(i, j)], c), *rest]

    return list(from_segment(0, None))


@pytest.mark.parametrize("n", [1, 2, 3, 5])
def test_log_partition_sums_every_split(n):
    rng = np.random.default_rng(n)
    spans = [(i, j) for i in range(n) for j in range(i + 1, n + 1)]
    scores, openings = rng.normal(size=(len(spans), 4)), rng.normal(size=max(0, n - 1))
    splits = every_split(n, spans, 4)
    brute = np.logaddexp.reduce([split_score(s, spans, scores, openings) for s in splits])
    got = log_partition(n, spans, torch.tensor(scores), torch.tensor(openings))
    assert float(got) == pytest.approx(brute, rel=1e-9)


def test_log_partition_is_differentiable_and_prefers_the_gold_split_after_a_step():
    n, spans = 3, [(i, j) for i in range(3) for j in range(i + 1, 4)]
    scores = torch.zeros(len(spans), 3, requires_grad=True)
    openings = torch.zeros(2, requires_grad=True)
    gold = [(spans.index((0, 1)), 0), (spans.index((1, 3)), 2)]
    nll = log_partition(n, spans, scores, openings) - split_score(gold, spans, scores, openings)
    nll.backward()
    with torch.no_grad():
        scores -= scores.grad
        openings -= openings.grad
    assert best_split(n, spans, scores.detach().numpy(), openings.detach().numpy()) == gold


@pytest.mark.parametrize("seed", range(5))
def test_best_split_is_the_highest_scoring_split(seed):
    rng = np.random.default_rng(seed)
    n = 5
    # Like the planner: some short spans are not allowed, the whole utterance always is.
    spans = [(i, j) for i in range(n) for j in range(i + 1, n + 1) if j - i != 2 or i == 1]
    scores, openings = rng.normal(size=(len(spans), 3)), rng.normal(size=n - 1)
    splits = every_split(n, spans, 3)
    best = max(splits, key=lambda s: split_score(s, spans, scores, openings))
    assert best_split(n, spans, scores, openings) == best


def test_gold_split_in_segment_ranges():
    example = single_act("x", "Yes, that works, and the room is upstairs.", "agreeing")
    assert example.gold_split() == [((0, len(example.pieces)), "agreeing")]
    two = multi_act({"id": "y", "text": "Yes, that works, and the room is upstairs.",
                     "labels": ["agreeing", "pointing"], "anchors": ["Yes", "the room is upstairs"]})
    assert two.gold_split() == [((0, 2), "agreeing"), ((2, 3), "pointing")]


def test_enumeration_counts_every_split():
    # Three segments, two classes: one act (2 ways) + two acts (2 cuts x 2) + three alternating acts (2) = 8.
    spans = [(i, j) for i in range(3) for j in range(i + 1, 4)]
    assert len(every_split(3, spans, 2)) == 8
