"""Single-label metrics: top-1 accuracy per tier, paired context accuracy, pass aggregation.

All accuracies are percentages (0-100), like the paper's tables. A prediction is a dict with at least
{"label", "pred", "pass"} ("tier" for the benchmark); pred is None when the planner failed on the item,
which counts as wrong. Over repeated passes we report the run-wise mean and the sample SD (ddof=1; None
for a single pass, where no spread can be estimated).
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Iterable, Sequence


def mean_sd(values: Sequence[float]) -> dict:
    """{"mean", "sd"}: arithmetic mean and sample standard deviation (None below two values)."""
    values = [float(v) for v in values]
    if not values:
        return {"mean": None, "sd": None}
    mean = sum(values) / len(values)
    if len(values) < 2:
        return {"mean": mean, "sd": None}
    var = sum((v - mean) ** 2 for v in values) / (len(values) - 1)
    return {"mean": mean, "sd": math.sqrt(var)}


def aggregate_passes(per_pass: Sequence[dict[str, float]]) -> dict[str, dict]:
    """[{metric: value} per pass] -> {metric: {"mean", "sd"}} over passes (metrics present in every pass)."""
    if not per_pass:
        return {}
    keys = [k for k in per_pass[0] if all(k in p and p[k] is not None for p in per_pass)]
    return {k: mean_sd([p[k] for p in per_pass]) for k in keys}


def accuracy(pairs: Iterable[tuple[str, str | None]]) -> float | None:
    """Percent of (label, pred) pairs with pred == label; None for no pairs."""
    pairs = list(pairs)
    if not pairs:
        return None
    return 100.0 * sum(pred == label for label, pred in pairs) / len(pairs)


def by_pass(predictions: Iterable[dict]) -> dict[int, list[dict]]:
    groups: dict[int, list[dict]] = defaultdict(list)
    for p in predictions:
        groups[p["pass"]].append(p)
    return dict(sorted(groups.items()))


def tier_accuracy(predictions: Sequence[dict], tiers: Sequence[str]) -> dict[str, dict]:
    """{tier: {mean, sd}, ..., "overall": {mean, sd}}: per-pass accuracy per tier, aggregated over passes.

    Tiers with no items are None. Overall is the accuracy over all items of a pass (not a mean of tiers).
    """
    per_pass = []
    for preds in by_pass(predictions).values():
        row = {t: accuracy((p["label"], p["pred"]) for p in preds if p["tier"] == t) for t in tiers}
        row["overall"] = accuracy((p["label"], p["pred"]) for p in preds)
        per_pass.append(row)
    aggregated = aggregate_passes(per_pass)
    return {k: aggregated.get(k) for k in (*tiers, "overall")}


def paired_context_accuracy(predictions: Sequence[dict]) -> dict:
    """Paired history ablation: each prediction has "pred_with" and "pred_without" for the same item.

    Per pass: accuracy with history, without, and their difference (the gain); each aggregated over
    passes. Also pooled discordant pairs: items right only with history / right only without.
    """
    per_pass, only_with, only_without = [], 0, 0
    for preds in by_pass(predictions).values():
        with_acc = accuracy((p["label"], p["pred_with"]) for p in preds)
        without_acc = accuracy((p["label"], p["pred_without"]) for p in preds)
        per_pass.append({"with_history": with_acc, "without_history": without_acc,
                         "gain": with_acc - without_acc})
        for p in preds:
            right_with, right_without = p["pred_with"] == p["label"], p["pred_without"] == p["label"]
            only_with += right_with and not right_without
            only_without += right_without and not right_with
    result = aggregate_passes(per_pass)
    result["per_pass"] = per_pass
    result["discordant"] = {"only_with_history": only_with, "only_without_history": only_without}
    return result
