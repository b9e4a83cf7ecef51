"""Figures of what a turn and a session did: a turn's speech-gesture timeline (words, each gesture's
motion span, trigger onset, planned, executed and simulated stroke), drawn live by sync_eval and from a
recording by the recording report, and a session's loop health and joints against their bounds."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from emopose.contract import EventKind
from emopose.joint_limits import JointLimits
from emopose.sync.joint_bounds import SPEED_RATIO_BOUND
from emopose.sync.strokes import ENDS


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")  # files only; never open a window
    import matplotlib.pyplot as plt

    return plt


def motion_spans(events, speech_start: float, record_of: dict[int, int]) -> dict[int, list[float]]:
    """record k -> the times (s from speech start) its command started and ended, from (t, kind, command
    id) events; record_of maps a command id to its record."""
    spans: dict[int, list[float]] = {}
    for t, kind, command_id in events:
        if command_id in record_of and kind in (EventKind.STARTED, *ENDS):
            spans.setdefault(record_of[command_id], []).append(t - speech_start)
    return spans


def plot_timelines(path: Path, item, turn, strokes) -> None:
    """One sync_eval item's turn (live objects) as a timeline figure."""
    events = [(e.t, e.kind, e.command_id) for e in turn.dispatched.events]
    record_of = {c.id: c.record for c in turn.submitted.commands}
    words = [(w.text, w.start_s) for w in turn.speech.words]
    draw_timeline(path, f"{item.id}: {item.text}", words,
                  motion_spans(events, turn.dispatched.speech_start, record_of), strokes)


def plot_recorded_turn(path: Path, title: str, timeline: dict, events, strokes) -> None:
    """A recorded /speech/timeline message, with the session's (t, kind, command id) events."""
    record_of = {g["command_id"]: g["k"] for g in timeline["gestures"] if g["command_id"] is not None}
    words = [(w["text"], w["start_s"]) for w in timeline["words"]]
    draw_timeline(path, title, words, motion_spans(events, timeline["speech_start"], record_of), strokes)


def draw_timeline(path: Path, title: str, words: list[tuple[str, float]], spans: dict[int, list[float]],
                  strokes) -> None:
    """words (text, onset s), record k -> motion span times, StrokeSync rows: one row per gesture."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(10, 1.2 + 0.45 * len(strokes)))
    for text, start_s in words:
        ax.axvline(start_s, color="0.85", lw=0.8, zorder=0)
        ax.text(start_s, len(strokes) + 0.1, text, rotation=45, fontsize=7, ha="left", va="bottom")
    labelled: set[str] = set()

    def mark(x: float | None, y: float, style: str, color: str, label: str, **kw) -> None:
        if x is not None:
            ax.plot(x, y, style, color=color, label=None if label in labelled else label, **kw)
            labelled.add(label)

    for row in strokes:
        y = len(strokes) - 1 - row.k
        if row.k in spans:
            span = spans[row.k]
            ax.plot([min(span), max(span)], [y, y], color="tab:blue", lw=6, alpha=0.35, solid_capstyle="butt")
        mark(row.onset_s, y, "|", "k", "trigger onset", ms=16, mew=2)
        mark(row.planned_s, y, "o", "tab:orange", "planned stroke", mfc="none")
        mark(row.executed_s, y, "x", "tab:red", "executed stroke")
        mark(row.simulated_s, y, "+", "tab:green", "simulated stroke", ms=10)
        label = f"{row.motion}" + (" (dropped)" if row.dropped else "")
        ax.text(-0.05, y, label, ha="right", va="center", fontsize=8, transform=ax.get_yaxis_transform())
    ax.set_yticks([])
    ax.set_ylim(-0.7, len(strokes) + 1.2)
    ax.set_xlabel("s from speech start")
    ax.set_title(title, fontsize=8, loc="left")
    if labelled:
        ax.legend(loc="lower right", fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_loop_health(path: Path, times: np.ndarray, dt: float, turn_starts: list[float]) -> None:
    """The gap before each command (ms; a gap over one period is skipped deadlines) and the commands sent
    in each whole second (the first and last, partial, left out), against session time, with each turn's
    speech start."""
    plt = _pyplot()
    gaps_ms = np.diff(times) * 1e3
    seconds = np.floor(times).astype(int)
    windows, counts = np.unique(seconds, return_counts=True)
    if windows.size > 2:
        windows, counts = windows[1:-1], counts[1:-1]
    fig, (gap_ax, rate_ax) = plt.subplots(2, 1, figsize=(10, 5), sharex=True)
    gap_ax.plot(times[1:], gaps_ms, ".", ms=3, color="tab:blue")
    gap_ax.axhline(dt * 1e3, color="0.5", lw=0.8, ls="--", label=f"period {dt * 1e3:.0f} ms")
    gap_ax.set_ylim(0, max(3e3 * dt, 1.1 * gaps_ms.max()))
    gap_ax.set_ylabel("gap before command (ms)")
    gap_ax.legend(loc="upper right", fontsize=7)
    rate_ax.step(windows, counts, where="post", color="tab:blue")
    rate_ax.axhline(1 / dt, color="0.5", lw=0.8, ls="--")
    rate_ax.set_ylabel("commands per second")
    rate_ax.set_xlabel("session time (s)")
    for ax in (gap_ax, rate_ax):
        for start in turn_starts:
            ax.axvline(start, color="tab:orange", lw=0.6, alpha=0.6)
    gap_ax.set_title("control loop: command gaps and rate (orange: a turn's speech start)", fontsize=9,
                     loc="left")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_joint_bounds(path: Path, times: np.ndarray, q: np.ndarray, limits: JointLimits) -> None:
    """Each joint's position as a share of its limit range (outside [0, 1]: past a hard limit) and the
    fastest joint's speed over its bound, against session time."""
    plt = _pyplot()
    share = (q - limits.lower) / (limits.upper - limits.lower)
    dt = np.diff(times)
    keep = dt > 1e-9
    ratio = (np.abs(np.diff(q, axis=0)[keep]) / dt[keep, None] / limits.max_velocity).max(axis=1)
    fig, (pos_ax, speed_ax) = plt.subplots(2, 1, figsize=(10, 6), sharex=True)
    for j, name in enumerate(limits.names):
        pos_ax.plot(times, share[:, j], lw=0.8, label=name.removesuffix("_joint"))
    for bound in (0.0, 1.0):
        pos_ax.axhline(bound, color="k", lw=1)
    pos_ax.set_ylim(min(-0.05, share.min() - 0.05), max(1.35, share.max() + 0.05))  # room for the legend
    pos_ax.set_ylabel("position in limit range")
    pos_ax.legend(loc="upper left", fontsize=5, ncol=7)
    speed_ax.plot(times[1:][keep], ratio, lw=0.8, color="tab:blue")
    speed_ax.axhline(SPEED_RATIO_BOUND, color="tab:red", lw=1, ls="--", label=f"{SPEED_RATIO_BOUND}x bound")
    speed_ax.set_ylabel("max |speed| / bound")
    speed_ax.set_xlabel("session time (s)")
    speed_ax.legend(loc="upper right", fontsize=7)
    pos_ax.set_title("simulated joints against the library's limits and speed bounds", fontsize=9,
                     loc="left")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
