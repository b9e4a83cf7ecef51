"""One item's speech-gesture timeline as a figure: words, each gesture's motion span, planned and
executed stroke starts (sync_eval draws a few per mode into the run directory)."""

from __future__ import annotations

from pathlib import Path

from emopose.contract import EventKind
from emopose.sync.strokes import ENDS


def plot_timelines(path: Path, item, turn, strokes) -> None:
    import matplotlib

    matplotlib.use("Agg")  # files only; never open a window
    import matplotlib.pyplot as plt

    speech_start = turn.dispatched.speech_start
    spans = {}
    for e in turn.dispatched.events:
        if e.command_id is not None and e.kind in (EventKind.STARTED, *ENDS):
            spans.setdefault(e.command_id, []).append(e.t - speech_start)
    by_record = {c.record: c for c in turn.submitted.commands}
    fig, ax = plt.subplots(figsize=(10, 1.2 + 0.45 * len(strokes)))
    for word in turn.speech.words:
        ax.axvline(word.start_s, color="0.85", lw=0.8, zorder=0)
        ax.text(word.start_s, len(strokes) + 0.1, word.text, rotation=45, fontsize=7, ha="left", va="bottom")
    for row in strokes:
        y = len(strokes) - 1 - row.k
        command = by_record.get(row.k)
        span = spans.get(command.id) if command is not None else None
        if span:
            ax.plot([min(span), max(span)], [y, y], color="tab:blue", lw=6, alpha=0.35, solid_capstyle="butt")
        if row.onset_s is not None:
            ax.plot(row.onset_s, y, "k|", ms=16, mew=2, label="trigger onset" if row.k == 0 else None)
        if row.planned_s is not None:
            ax.plot(row.planned_s, y, "o", mfc="none", color="tab:orange",
                    label="planned stroke" if row.k == 0 else None)
        if row.executed_s is not None:
            ax.plot(row.executed_s, y, "x", color="tab:red", label="executed stroke" if row.k == 0 else None)
        label = f"{row.motion}" + (" (dropped)" if row.dropped else "")
        ax.text(-0.05, y, label, ha="right", va="center", fontsize=8, transform=ax.get_yaxis_transform())
    ax.set_yticks([])
    ax.set_ylim(-0.7, len(strokes) + 1.2)
    ax.set_xlabel("s from speech start")
    ax.set_title(f"{item.id}: {item.text}", fontsize=8, loc="left")
    ax.legend(loc="lower right", fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
