"""+experiment=sync_eval: how close gestures are released to the true onset of their trigger phrase.

Each sequence-suite item becomes a turn whose reply is the item's text and whose plan is its
annotated labels/anchors/variants (no planner, so only scheduling is measured). For each schedule mode
(anchor: the paper's Eq. schedule; words: the engine's word onsets) the turn runs through resolve,
modulate, schedule, sequence and dispatch on dry_run with virtual time, and every released gesture is
compared with the true onset of its trigger phrase (espeak's word events, or piper's alignments):
  scheduled vs onset: the schedule's release time (what the scheduler decided);
  actual vs onset:    the sequencer's "started" event (what the robot did): the 50 Hz tick grid adds
                      0..20 ms, and a gesture whose predecessor is still running waits for it to end
                      (plus the <= 0.3 s blend), which no schedule can undo.
  stroke vs onset:    where the executed stroke lands (emopose.sync.strokes.py): the first tick
                      at which the command stream, and with a simulator the joint stream, reaches the
                      gesture's stroke-start keyframe; this is the measure the timeline mode is built for.
With job.plans=planner the configured planner plans each text: strokes are then measured against its own
trigger and the act's gold anchor (emopose/sync/affiliate.py; a clause-long trigger lands early for the
words the gesture belongs to). A few items per mode are drawn as timelines into the run directory.
"""

from __future__ import annotations

import itertools
import logging
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from emopose.backends.stream_tap import StreamTap
from emopose.bench.suites import SequenceItem, load_sequence
from emopose.contract import Plan
from emopose.planners.base import PlanRequest
from emopose.resources import Resources, Run
from emopose.results import JobOutput, markdown_table
from emopose.stages.parse import parse_output
from emopose.sync.affiliate import gold_anchor_strokes
from emopose.sync.plot import plot_timelines
from emopose.sync.strokes import (
    Streams,
    StrokeSync,
    measure_strokes,
    planned_strokes,
    stroke_summary,
    unmet_targets,
)
from emopose.sync.words import (
    GestureSync,
    annotated_spans,
    measure_turn,
    require_true_onsets,
    summarize,
    true_word_events,
    tts_settings,
)
from emopose.turn.pipeline import Pipeline
from emopose.turn.runner import TurnRunner

log = logging.getLogger(__name__)


@dataclass
class SyncEvalJob:
    suite: str
    fallback_suite: str | None = None
    modes: list[str] = field(default_factory=lambda: ["anchor", "words", "timeline"])
    limit: int | None = None
    target_p95_ms: float = 60.0  # words mode, scheduled vs onset
    plots: int = 4               # items drawn as timelines per mode
    stroke_targets: dict[str, float] = field(default_factory=dict)  # stroke_summary key -> bound (see yaml)
    plans: str = "annotation"  # annotation: the gold records; planner: the configured planner's

    def __call__(self, run: Run) -> JobOutput:
        res = run.resources
        require_true_onsets(res.synthesizer)
        if res.clock.realtime:
            raise ValueError("sync_eval runs on virtual time: use backend=dry_run with run.clock=auto")
        if self.plans not in ("annotation", "planner"):
            raise ValueError(f"job.plans must be annotation or planner, got {self.plans!r}")
        suite_path, items = self._items()
        plans = [self._plan(res, item) for item in items]
        run.session.open()
        tap = run.session.tap(StreamTap)
        rows: dict[str, list[GestureSync]] = {}
        strokes: dict[str, list[StrokeSync]] = {}
        gold: dict[str, list[StrokeSync]] = {}
        for mode in self.modes:
            runner = run.runner.with_pipeline(self._pipeline(res.pipeline, mode))
            rows[mode], strokes[mode], gold[mode] = [], [], []
            for number, (item, plan) in enumerate(zip(items, plans)):
                sync, stroke, gold_rows, turn = self._run_item(res, runner, item, plan, tap)
                rows[mode] += sync
                strokes[mode] += stroke
                gold[mode] += gold_rows
                if number < self.plots:
                    plot_timelines(res.run_dir / f"timeline_{mode}_{item.id}.png", item, turn, stroke)
        results = self._results(run, suite_path, items, rows, strokes, gold, simulated=tap.simulated)
        return results, self._markdown(results)

    def _items(self) -> tuple[Path, list[SequenceItem]]:
        """The suite's items (the first `limit`); an anchor missing from its text is kept: the say-do
        check reports it."""
        path = Path(self.suite)
        if not path.exists():
            if not self.fallback_suite:
                raise FileNotFoundError(f"job.suite {path} does not exist "
                                        "(set job.suite or job.fallback_suite)")
            log.warning("sequence suite %s is missing; measuring the fixture %s instead",
                        path, self.fallback_suite)
            path = Path(self.fallback_suite)
        return path, load_sequence(path, anchors_in_text=False)[:self.limit]

    @staticmethod
    def _pipeline(configured: Pipeline, mode: str) -> Pipeline:
        """The configured stages from resolve on, scheduled in `mode`, queueing (no interrupt), and
        dispatched until rest, so each item starts from rest with an empty queue."""
        stages = {n: configured.get(n) for n in ("resolve", "modulate", "schedule", "sequence", "dispatch")}
        missing = [n for n, stage in stages.items() if stage is None]
        if missing:
            raise ValueError(f"sync_eval needs pipeline stages {missing}; pipeline has {configured.names}")
        return Pipeline([stages["resolve"], stages["modulate"], stages["schedule"].in_mode(mode),
                         stages["sequence"].queueing(), stages["dispatch"].waiting_until("rest")],
                        inputs=("request", "plan"))

    def _plan(self, res: Resources, item: SequenceItem) -> Plan:
        """The item's annotation, or the planner's plan of its text (its reply must be the text; one the
        parser cut to MAX_REPLY_CHARS is restored, so every record is measured on the whole text)."""
        if self.plans == "annotation":
            return item.plan()
        plan = parse_output(res.planner.plan(PlanRequest(item.text)), item.text)
        if plan.reply != item.text and item.text.startswith(plan.reply):
            plan = plan.model_copy(update={"reply": item.text})
        if plan.reply != item.text:
            raise ValueError(f"job.plans=planner needs a planner that narrates the text as given; "
                             f"{res.planner.name} replied {plan.reply[:60]!r} to item {item.id}")
        return plan

    def _run_item(self, res: Resources, runner: TurnRunner, item: SequenceItem, plan: Plan, tap: StreamTap):
        """Run one plan; its gestures measured against their triggers (sync, strokes) and against the
        item's gold anchors (the same with the annotation as the plan)."""
        first = len(tap)
        turn = runner.run_plan(plan, utterance=item.text)
        if not turn.dispatched.completed:
            log.warning("item %s did not come to rest within the dispatch timeout", item.id)
        planned = SequenceItem(item.id, item.text, tuple(r.cls for r in plan.records),
                               tuple(r.trigger or "" for r in plan.records),
                               tuple(r.variant or "" for r in plan.records))
        events = true_word_events(res.synthesizer, turn.speech)
        sync = measure_turn(planned, turn, events)
        loop = runner.session.loop
        times = np.asarray(tap.times[first:]) + (loop.clock.now() - loop.stream_time)  # stream -> clock time
        simulated = tap.simulated
        streams = Streams([(e.t, e.kind, e.command_id) for e in turn.dispatched.events],
                          turn.dispatched.speech_start, times, np.asarray(tap.commands[first:]),
                          times + loop.dt if simulated else None,
                          np.asarray(tap.states[first:]) if simulated else None)
        strokes = measure_strokes(item.id, planned_strokes(turn), [r.onset_s for r in sync], streams,
                                  turn.schedule.preroll_s)
        gold = gold_anchor_strokes(item.id, item.text, annotated_spans(item.text, item.anchors),
                                   planned.anchors, strokes, events)
        return sync, strokes, gold, turn

    def _results(self, run: Run, suite_path: Path, items: list[SequenceItem], rows: dict, strokes: dict,
                 gold: dict, simulated: bool) -> dict:
        summaries = {mode: summarize(r) for mode, r in rows.items()}
        for mode in strokes:
            for key, sim in (("", False), ("_simulated", True))[:1 + simulated]:
                for name, measured in (("stroke_vs_onset", strokes), ("stroke_vs_gold_anchor", gold)):
                    summary = stroke_summary(measured[mode], simulated=sim)
                    unmet = unmet_targets(summary, self.stroke_targets)
                    summaries[mode][name + key] = {**summary, "unmet_targets": unmet}
        missing = [{"item": r.item, "k": r.k, "trigger": r.trigger}
                   for r in next(iter(rows.values()), []) if not r.found]
        for m in missing:
            log.warning("say-do check: item %s record %d trigger %r is not in the reply",
                        m["item"], m["k"], m["trigger"])
        words_p95 = summaries.get("words", {}).get("scheduled_vs_onset", {}).get("p95_abs_ms")
        return {
            "suite": str(suite_path), "items": len(items), "plans": self.plans,
            "tts": tts_settings(run.resources.synthesizer),
            "control_dt_s": run.session.loop.dt, "modes": summaries,
            "target": {"words_p95_scheduled_vs_onset_ms": self.target_p95_ms, "value_ms": words_p95,
                       "met": words_p95 is not None and words_p95 <= self.target_p95_ms},
            "stroke_targets": self.stroke_targets,
            "say_do": {"missing": len(missing), "records": missing},
            "gestures": {mode: [r.as_json() for r in mode_rows] for mode, mode_rows in rows.items()},
            "strokes": {mode: [r.as_json() for r in mode_rows] for mode, mode_rows in strokes.items()},
        }

    @staticmethod
    def _markdown(results: dict) -> str:
        target, say_do = results["target"], results["say_do"]
        flagged = ", ".join(f"{m['item']}#{m['k']} {m['trigger']!r}" for m in say_do["records"]) or "none"
        return (f"# Speech-gesture sync ({results['items']} items from {results['suite']})\n\n"
                f"True onsets: {', '.join(f'{k} {v}' for k, v in results['tts'].items())}.\n\n"
                f"{_release_table(results['modes'])}\n\n"
                "## Where the executed strokes land\n\nExecuted stroke start: the first tick at which the "
                "stream comes within 0.05 rad of the gesture's stroke-start keyframe; offset from the "
                "trigger word's onset, and from the onset of the gold anchor the gesture belongs to (the "
                "same with job.plans=annotation), negative: before it. Targets (within: at least; the "
                f"others: at most): {results['stroke_targets']}.\n\n{_stroke_table(results['modes'])}\n\n"
                f"Target: words-mode p95 |scheduled - onset| <= "
                f"{target['words_p95_scheduled_vs_onset_ms']:.0f} ms: "
                f"{'met' if target['met'] else 'NOT met'} ({target['value_ms']}).\n\n"
                f"Say-do check: {say_do['missing']} record(s) whose trigger is not in the reply: "
                f"{flagged}.\n\n"
                "scheduled vs onset is the scheduler's error; actual vs onset adds what execution does: the "
                "sequencer releases only on 50 Hz ticks (0-20 ms later), and a gesture whose predecessor is "
                "still running starts only after it ends plus the <= 0.3 s blend (\"queued\"); unqueued p95 "
                "leaves those out. The anchor equation aims at the phrase center, not its onset; "
                "scheduled-center shows its error against that target (center: midway between the phrase "
                "onset and the next word's onset).\n")


def _ms(stats: dict, key: str) -> str:
    return "-" if stats[key] is None else f"{stats[key]:.0f}"


def _release_table(modes: dict) -> str:
    """Scheduled and actual release times against the onsets, per mode."""
    header = ["mode", "gestures", "measured", "scheduled-onset mean abs (ms)", "p95", "mean signed",
              "actual-onset mean abs (ms)", "p95", "p95 unqueued", "queued", "queue delay mean (ms)",
              "scheduled-center p95 (ms)"]
    rows = []
    for mode, s in modes.items():
        sched, actual, unq = s["scheduled_vs_onset"], s["actual_vs_onset"], s["actual_vs_onset_unqueued"]
        rows.append([mode, s["gestures"], s["measured"], _ms(sched, "mean_abs_ms"), _ms(sched, "p95_abs_ms"),
                     _ms(sched, "mean_signed_ms"), _ms(actual, "mean_abs_ms"), _ms(actual, "p95_abs_ms"),
                     _ms(unq, "p95_abs_ms"), s["queued"], _ms(s["queue_delay"], "mean_abs_ms"),
                     _ms(s["scheduled_vs_center"], "p95_abs_ms")])
    return markdown_table(header, rows)


def _stroke_table(modes: dict) -> str:
    """Where the executed strokes land, per mode and stream (command, and simulated when there is one)."""
    header = ["mode", "stream", "against", "planned", "arrived", "within [-200, +100] ms",
              "median |offset| (ms)", "p95 (ms)", "median signed (ms)", "dropped", "pre-roll p95 (ms)",
              "targets"]
    rows = []
    for mode, s in modes.items():
        for (stream, suffix), (against, name) in itertools.product(
                (("command", ""), ("simulated", "_simulated")),
                (("trigger", "stroke_vs_onset"), ("gold anchor", "stroke_vs_gold_anchor"))):
            if (key := name + suffix) in s:
                st = s[key]
                rows.append([mode, stream, against, st["n"], st["arrived"],
                             f"{st['within_window_share']:.3f}",
                             _ms(st, "median_abs_ms"), _ms(st, "p95_abs_ms"), _ms(st, "median_signed_ms"),
                             f"{st['dropped_share']:.3f}", f"{st['preroll_p95_ms']:.0f}",
                             "met" if not st["unmet_targets"] else "missed"])
    return markdown_table(header, rows)
