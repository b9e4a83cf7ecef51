"""Where executed strokes land against their words, measured from the joint streams.

A gesture's executed stroke start is the first tick, between its "started" event and the end of its
motion, at which the stream comes within `tolerance` rad (max over joints) of the gesture's modulated
stroke-start keyframe. The command stream is what the robot was told; a simulated stream (MuJoCo) is
what its joints did, each sample stamped at the end of its control period. Results are relative to
the start of the speech audio, like the trigger word's onset they are compared with. The same
computation runs live (sync_eval) and on a recording (emopose/sync/recording.py).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from emopose import STROKE_TOLERANCE
from emopose.contract import EventKind

WINDOW_S = (-0.2, 0.1)  # a stroke belongs to its word when it lands 200 ms before to 100 ms after the onset
EDGE_MS = 1e-3  # stream times carry ~1e-12 s of float noise: a stroke on a window edge is inside it
ENDS = (EventKind.COMPLETED, EventKind.CUT, EventKind.STOPPED)


@dataclass(frozen=True)
class PlannedStroke:
    """What measuring one planned gesture needs: its command (None if dropped) and stroke keyframe."""

    k: int
    motion: str
    command_id: int | None
    keyframe: np.ndarray
    planned_s: float | None  # the timeline's planned arrival, from speech start (None in the paper's modes)
    dropped: str | None


@dataclass(frozen=True)
class StrokeSync:
    item: str
    k: int
    motion: str
    onset_s: float | None       # the trigger word's onset
    planned_s: float | None
    executed_s: float | None    # command stream
    simulated_s: float | None   # simulated joint stream, where there is one
    dropped: str | None
    preroll_s: float

    def as_json(self) -> dict:
        return asdict(self)


def planned_strokes(turn) -> list[PlannedStroke]:
    commands = {c.record: c for c in turn.submitted.commands}
    out = []
    for k, (gesture, release) in enumerate(zip(turn.schedule.gestures, turn.schedule.releases)):
        command = commands.get(k)
        keyframe = np.asarray(gesture.keyframes)[gesture.resolved.entry.stroke_span[0]]
        planned = release.timing.arrival_s if release.timing is not None else None
        out.append(PlannedStroke(k, gesture.name, None if command is None else command.id, keyframe, planned,
                                 release.dropped))
    return out


def first_within(stream: np.ndarray, keyframe: np.ndarray, tolerance: float = STROKE_TOLERANCE) -> int | None:
    """Index of the first (T, 14) sample with every joint within `tolerance` of `keyframe`, else None."""
    hits = np.flatnonzero(np.max(np.abs(stream - keyframe), axis=1) <= tolerance)
    return int(hits[0]) if hits.size else None


def first_arrival(times: np.ndarray, stream: np.ndarray, keyframe: np.ndarray, start: float, end: float,
                  tolerance: float) -> float | None:
    """Time of the first sample in [start, end] within `tolerance` of `keyframe`, else None."""
    inside = np.flatnonzero((times >= start - 1e-9) & (times <= end + 1e-9))
    hit = first_within(stream[inside], keyframe, tolerance) if inside.size else None
    return None if hit is None else float(times[inside[hit]])


@dataclass(frozen=True)
class Streams:
    """One time base (any: stream or clock time) for the events, the speech start and the samples."""

    events: list[tuple[float, str, int | None]]  # (t, kind, command id)
    speech_start: float
    command_times: np.ndarray
    commands: np.ndarray
    state_times: np.ndarray | None = None  # the simulated pose's stamps (end of each control period)
    states: np.ndarray | None = None


def measure_strokes(item: str, planned: list[PlannedStroke], onsets: list[float | None], streams: Streams,
                    preroll_s: float, tolerance: float = STROKE_TOLERANCE) -> list[StrokeSync]:
    started = {cid: t for t, kind, cid in streams.events if kind == EventKind.STARTED}
    ended = {cid: t for t, kind, cid in streams.events if kind in ENDS}
    rows = []
    for p in planned:
        executed = simulated = None
        if p.command_id in started:
            start = started[p.command_id]
            end = ended.get(p.command_id, float(streams.command_times[-1]))
            executed = first_arrival(streams.command_times, streams.commands, p.keyframe, start, end,
                                     tolerance)
            if streams.states is not None:
                dt = float(streams.state_times[0] - streams.command_times[0])
                simulated = first_arrival(streams.state_times, streams.states, p.keyframe, start, end + dt,
                                          tolerance)
        speech = streams.speech_start
        rows.append(StrokeSync(item, p.k, p.motion, onsets[p.k], p.planned_s,
                               None if executed is None else executed - speech,
                               None if simulated is None else simulated - speech, p.dropped, preroll_s))
    return rows


def stroke_summary(rows: list[StrokeSync], simulated: bool = False) -> dict:
    """The measure over gestures with a known onset: |executed - onset| statistics over those that
    arrived, the share of all planned gestures inside WINDOW_S, drops and the pre-roll."""
    planned = [r for r in rows if r.onset_s is not None]
    landed = [(r.simulated_s if simulated else r.executed_s) for r in planned]
    offsets = np.array([t - r.onset_s for t, r in zip(landed, planned) if t is not None]) * 1e3
    low, high = (w * 1e3 for w in WINDOW_S)
    prerolls = np.array([r.preroll_s for r in rows if r.k == 0] or [0.0]) * 1e3
    n = len(planned)

    def stat(fn) -> float | None:
        return float(fn(offsets)) if offsets.size else None

    return {
        "n": n, "arrived": int(offsets.size),
        "median_abs_ms": stat(lambda x: np.median(np.abs(x))),
        "p95_abs_ms": stat(lambda x: np.percentile(np.abs(x), 95)),
        "median_signed_ms": stat(np.median),
        "within_window_share": float(np.sum((offsets >= low - EDGE_MS) & (offsets <= high + EDGE_MS)) / n)
        if n else None,
        "dropped_share": sum(r.dropped is not None for r in planned) / n if n else None,
        "preroll_p95_ms": float(np.percentile(prerolls, 95)),
        "window_ms": [low, high],
    }


def unmet_targets(summary: dict, targets: dict[str, float]) -> list[str]:
    """Which targets ({"within_window_share": minimum, the other keys: maxima}) a stroke summary misses."""
    def misses(key: str, bound: float) -> bool:
        value = summary[key]
        if value is None:
            return True
        return value < bound if key == "within_window_share" else value > bound

    return [f"{key} {summary[key]} vs {bound}" for key, bound in targets.items() if misses(key, bound)]

