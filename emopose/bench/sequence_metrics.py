"""Ordered multi-action metrics for the sequence suite (paper Table extensions).

For one item, gold is the annotated class sequence g (length n, with anchors and variants) and the
prediction is the planner's ordered records p (length m; a failed item has no prediction). Per pass:

- primary-class accuracy: p[0] == g[0].
- ordered exact match: p == g (same length, same classes, same order).
- aligned-step accuracy: position-wise agreement over the longer sequence,
  sum_{i < min(n, m)} [p_i == g_i] / max(n, m), averaged over items. Extra or missing steps count as
  misses, so over- and under-segmentation both cost.
- class-multiset F1: per item, overlap = |multiset(p) & multiset(g)|, P = overlap / m, R = overlap / n,
  F1 = 2PR / (P + R) (0 when overlap is 0), averaged over items; order is ignored.
- input-anchor recall: an annotated anchor is recalled when some predicted record's trigger, located
  in the input text (case-insensitive, every occurrence), overlaps the anchor's character span.
  Pooled over all annotated anchors.
- exact-variant match: annotated position k counts when the predicted record at position k names
  exactly variants[k] (the requested variant, before resolution; none never matches). Pooled over
  annotated positions.
- exact by gold length (2/3/4): ordered exact match within each length.
- over-/under-segmentation: counts of items with m > n / m < n (failed items are neither).
All rates are percentages; a failed item scores zero on every rate.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass

from emopose.bench.suites import SequenceItem


@dataclass(frozen=True)
class SequencePrediction:
    """The ordered records a planner returned for one item; `classes` is None when it failed."""

    classes: tuple[str, ...] | None
    triggers: tuple[str | None, ...] = ()
    variants: tuple[str | None, ...] = ()


def aligned_step_accuracy(gold: Sequence[str], pred: Sequence[str]) -> float:
    longest = max(len(gold), len(pred))
    if longest == 0:
        return 1.0
    return sum(g == p for g, p in zip(gold, pred)) / longest


def multiset_f1(gold: Sequence[str], pred: Sequence[str]) -> float:
    overlap = sum((Counter(gold) & Counter(pred)).values())
    if overlap == 0:
        return 0.0
    precision, recall = overlap / len(pred), overlap / len(gold)
    return 2 * precision * recall / (precision + recall)


def trigger_spans(text: str, trigger: str | None) -> list[tuple[int, int]]:
    """Every case-insensitive occurrence of the trigger in the text."""
    needle = (trigger or "").strip().lower()
    if not needle:
        return []
    haystack, spans, at = text.lower(), [], 0
    while (at := haystack.find(needle, at)) >= 0:
        spans.append((at, at + len(needle)))
        at += 1
    return spans


def anchors_recalled(item: SequenceItem, triggers: Sequence[str | None]) -> int:
    found = [span for t in triggers for span in trigger_spans(item.text, t)]
    return sum(any(s < end and start < e for s, e in found) for start, end in item.spans)


def item_scores(item: SequenceItem, pred: SequencePrediction) -> dict:
    gold, n = item.labels, len(item.labels)
    if pred.classes is None:
        return {"primary": 0, "exact": 0, "aligned": 0.0, "f1": 0.0, "anchors_hit": 0, "variants_hit": 0,
                "over": 0, "under": 0, "failed": 1}
    classes, m = pred.classes, len(pred.classes)
    variants_hit = sum(k < len(pred.variants) and pred.variants[k] == v for k, v in enumerate(item.variants))
    return {
        "primary": int(m > 0 and classes[0] == gold[0]),
        "exact": int(tuple(classes) == tuple(gold)),
        "aligned": aligned_step_accuracy(gold, classes),
        "f1": multiset_f1(gold, classes),
        "anchors_hit": anchors_recalled(item, pred.triggers),
        "variants_hit": variants_hit,
        "over": int(m > n),
        "under": int(m < n),
        "failed": 0,
    }


def suite_scores(items: Sequence[SequenceItem], preds: Sequence[SequencePrediction]) -> dict:
    """One pass over the suite -> rates (%) and counts (see the module docstring)."""
    if len(items) != len(preds):
        raise ValueError(f"{len(items)} items but {len(preds)} predictions")
    scores = [item_scores(i, p) for i, p in zip(items, preds)]
    n_items = len(items)
    positions = sum(len(i.labels) for i in items)

    def rate(key: str, denominator: int) -> float | None:
        return 100.0 * sum(s[key] for s in scores) / denominator if denominator else None

    result = {
        "primary_class": rate("primary", n_items),
        "ordered_exact": rate("exact", n_items),
        "aligned_step": rate("aligned", n_items),
        "multiset_f1": rate("f1", n_items),
        "anchor_recall": rate("anchors_hit", positions),
        "exact_variant": rate("variants_hit", positions),
    }
    for length in sorted({len(i.labels) for i in items}):
        subset = [s for i, s in zip(items, scores) if len(i.labels) == length]
        result[f"exact_len{length}"] = 100.0 * sum(s["exact"] for s in subset) / len(subset)
    result.update({k: sum(s[k] for s in scores) for k in ("over", "under", "failed")})
    return result
