"""Pooled confusion matrices and the paper-style figure (one panel per tier).

Rows are annotated classes, columns predicted classes, in the paper's class order. Cells show pooled
counts over all passes; colour is the row-normalised percentage. Failed predictions (pred None) are
left out of the matrix and reported in the panel title.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from emopose import CLASSES

ABBREVIATIONS = {"pointing": "Poi", "emphasizing": "Emp", "rejecting": "Rej", "agreeing": "Agr",
                 "doubting": "Dou", "welcoming": "Wel", "comforting": "Com", "neutral": "Neu"}


@dataclass(frozen=True)
class ConfusionPanel:
    title: str
    counts: np.ndarray  # (8, 8) ints, rows = annotated class, columns = predicted class
    failed: int = 0


def confusion_counts(pairs: Sequence[tuple[str, str | None]]) -> tuple[np.ndarray, int]:
    """(8, 8) pooled counts from (label, pred) pairs, and the number of failed (None) predictions."""
    index = {c: k for k, c in enumerate(CLASSES)}
    counts = np.zeros((len(CLASSES), len(CLASSES)), dtype=int)
    failed = 0
    for label, pred in pairs:
        if pred is None:
            failed += 1
        else:
            counts[index[label], index[pred]] += 1
    return counts, failed


def row_normalised(counts: np.ndarray) -> np.ndarray:
    totals = counts.sum(axis=1, keepdims=True)
    return 100.0 * counts / np.where(totals > 0, totals, 1)


def plot_confusion(panels: Sequence[ConfusionPanel], path: str | Path, suptitle: str | None = None) -> Path:
    """Write a PNG with one annotated confusion matrix per panel, side by side."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path = Path(path)
    labels = [ABBREVIATIONS[c] for c in CLASSES]
    fig, axes = plt.subplots(1, len(panels), figsize=(4.2 * len(panels) + 1.0, 4.6), squeeze=False,
                             layout="constrained")
    image = None
    for k, (ax, panel) in enumerate(zip(axes[0], panels)):
        percent = row_normalised(panel.counts)
        image = ax.imshow(percent, cmap="Blues", vmin=0, vmax=100)
        for i in range(len(CLASSES)):
            for j in range(len(CLASSES)):
                if panel.counts[i, j]:
                    ax.text(j, i, str(panel.counts[i, j]), ha="center", va="center", fontsize=8,
                            color="white" if percent[i, j] > 55 else "black")
        ax.set_xticks(range(len(CLASSES)), labels, rotation=45)
        ax.set_yticks(range(len(CLASSES)), labels)
        ax.set_xlabel("Predicted")
        if k == 0:
            ax.set_ylabel("Annotated")
        title = panel.title + (f"\n({panel.failed} failed, not shown)" if panel.failed else "")
        ax.set_title(title, fontsize=10)
    if image is not None:
        fig.colorbar(image, ax=list(axes[0]), shrink=0.8, label="row-normalised %")
    if suptitle:
        fig.suptitle(suptitle)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=130, bbox_inches="tight")
    plt.close(fig)
    return path
