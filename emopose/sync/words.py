"""Measured speech-gesture sync for one suite item: release times against the engine's true onsets.

For gesture k with trigger t_k: the true onset is the engine's first word event inside t_k's
annotated occurrence in the reply (anchors are matched in order, so a repeated anchor is measured at
the occurrence the annotator meant, while the schedule uses the first one, as the paper does);
`scheduled` is the schedule's release_s; `actual` is the sequencer's "started" event minus the
speech start. All are relative to the start of the audio. The phrase's true center (midway between its
onset and the next spoken word's onset, or T_a) is kept too: it is what the paper's anchor equation
aims at, so "scheduled vs center" separates its character-for-time error from its choice of target.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from emopose import CONTROL_DT
from emopose.bench.suites import SequenceItem
from emopose.contract import EventKind, trigger_position
from emopose.speech.clip import SpeechClip
from emopose.speech.espeak_lib import WordEvent
from emopose.speech.word_events import clean_events, onset_of_span

TRUE_ONSET_ENGINES = ("espeak", "piper")  # engines whose word onsets are measured, not estimated


def require_true_onsets(synthesizer) -> None:
    if synthesizer.name not in TRUE_ONSET_ENGINES:
        raise ValueError(f"sync_eval measures against true word onsets, but tts is {synthesizer.name!r} "
                         f"(estimated onsets): run it with tts=espeak or tts=piper")


def tts_settings(synthesizer) -> dict:
    """What the onsets came from, for results.json: the engine and its voice settings."""
    if synthesizer.name == "piper":
        return {"engine": "piper", "voice": synthesizer.model_id, "length_scale": synthesizer.length_scale}
    return {"engine": synthesizer.name, "voice": synthesizer.voice, "rate": synthesizer.rate}


def true_word_events(synthesizer, clip: SpeechClip) -> tuple[WordEvent, ...]:
    """The true word onsets of a clip that played: espeak's own word events, or piper's onsets from its
    phoneme alignments (the clip's words: piper samples anew each render, so only the played clip counts)."""
    require_true_onsets(synthesizer)
    if synthesizer.name == "espeak":
        return synthesizer.word_events(clip.text)
    if clip.estimated:
        raise ValueError(f"{synthesizer.name} gave no alignments for {clip.text[:60]!r}: its onsets are "
                         "estimated, so sync_eval cannot measure against them")
    return tuple(WordEvent(w.char_start, w.char_end - w.char_start, w.start_s) for w in clip.words)


def annotated_spans(text: str, anchors: tuple[str, ...]) -> list[tuple[int, int] | None]:
    """Each anchor's occurrence, searched in order after the previous one (first occurrence as fallback).

    Unlike the suite loader's exact check (emopose.bench.suites.anchor_spans) this is case-insensitive
    and keeps a missing anchor as None: the say-do check reports it instead of refusing the item."""
    spans: list[tuple[int, int] | None] = []
    cursor, lowered = 0, text.lower()
    for anchor in anchors:
        if not anchor:
            spans.append(None)
            continue
        pos = lowered.find(anchor.lower(), cursor)
        pos = pos if pos >= 0 else lowered.find(anchor.lower())
        spans.append((pos, pos + len(anchor)) if pos >= 0 else None)
        if pos >= 0:
            cursor = pos + len(anchor)
    return spans


@dataclass(frozen=True)
class GestureSync:
    item: str
    k: int
    motion: str
    trigger: str | None
    found: bool                     # the say-do check: the trigger occurs in the reply
    first_occurrence: bool          # the schedule's first-occurrence rule picks the annotated occurrence
    how: str
    scheduled_s: float
    onset_s: float | None           # the engine's true onset of the trigger phrase
    center_s: float | None          # midway between that onset and the next spoken word's onset
    actual_s: float | None          # the sequencer's "started" event, relative to the audio start
    queued: bool                    # started later than one tick after its release (waited in the queue)

    @property
    def measured(self) -> bool:
        return self.found and self.onset_s is not None

    def as_json(self) -> dict:
        return asdict(self)


def measure_turn(item: SequenceItem, turn, events) -> list[GestureSync]:
    schedule, submitted, dispatched = turn.schedule, turn.submitted, turn.dispatched
    started = {e.command_id: e.t for e in dispatched.events if e.kind == EventKind.STARTED}
    spans = annotated_spans(item.text, item.anchors)
    kept = clean_events(item.text, events)
    rows = []
    commands = {c.record: c for c in submitted.commands}
    for k, (gesture, release) in enumerate(zip(schedule.gestures, schedule.releases)):
        command = commands.get(k)
        span, trigger = spans[k], item.anchors[k]
        onset = onset_of_span(item.text, events, *span) if span else None
        after = [t for i, t in kept.items() if span and i >= span[1]]
        center = (onset + min(after, default=turn.speech.duration_s)) / 2 if onset is not None else None
        actual = (started[command.id] - dispatched.speech_start
                  if command is not None and command.id in started else None)
        queued = actual is not None and actual - release.release_s > CONTROL_DT + 1e-9
        first = span is not None and trigger_position(item.text, trigger) == span[0]
        rows.append(GestureSync(item.id, k, gesture.name, trigger, release.trigger_found, first,
                                release.how, release.release_s, onset, center, actual, queued))
    return rows


def offset_stats(offsets_s: list[float]) -> dict:
    """mean/p95/max of |offset| and the mean signed offset, in ms (positive: after the onset)."""
    if not offsets_s:
        return {"n": 0, "mean_abs_ms": None, "p95_abs_ms": None, "max_abs_ms": None, "mean_signed_ms": None}
    x = np.asarray(offsets_s) * 1e3
    return {"n": int(x.size), "mean_abs_ms": float(np.abs(x).mean()),
            "p95_abs_ms": float(np.percentile(np.abs(x), 95)), "max_abs_ms": float(np.abs(x).max()),
            "mean_signed_ms": float(x.mean())}


def summarize(rows: list[GestureSync]) -> dict:
    measured = [r for r in rows if r.measured]
    ran = [r for r in measured if r.actual_s is not None]
    queued = [r for r in ran if r.queued]
    hows: dict[str, int] = {}
    for r in rows:
        hows[r.how] = hows.get(r.how, 0) + 1
    return {
        "gestures": len(rows), "measured": len(measured), "missing_trigger": sum(not r.found for r in rows),
        "not_started": sum(r.actual_s is None for r in rows), "release_how": hows,
        "first_occurrence_mismatch": sum(r.found and r.onset_s is not None and not r.first_occurrence
                                         for r in rows),
        "scheduled_vs_onset": offset_stats([r.scheduled_s - r.onset_s for r in measured]),
        "scheduled_vs_center": offset_stats([r.scheduled_s - r.center_s for r in measured]),
        "actual_vs_onset": offset_stats([r.actual_s - r.onset_s for r in ran]),
        "actual_vs_onset_unqueued": offset_stats([r.actual_s - r.onset_s for r in ran if not r.queued]),
        "queued": len(queued),
        "queue_delay": offset_stats([r.actual_s - r.scheduled_s for r in queued]),
        "tick_delay": offset_stats([r.actual_s - r.scheduled_s for r in ran if not r.queued]),
    }
