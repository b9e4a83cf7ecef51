"""+experiment=sync_eval: how close gestures are released to the true onset of their trigger phrase.

Each sequence-suite item becomes a turn whose reply is the item's text and whose plan is its
annotated labels/anchors/variants (no planner, so only scheduling is measured). For each schedule mode
(anchor: the paper's Eq. schedule; words: the engine's word onsets) the turn runs through resolve,
modulate, schedule, sequence and dispatch on the configured backend (dry_run) with virtual time, and
every released gesture is compared with the onset espeak reports for its trigger phrase:
  scheduled vs onset: the schedule's release time (what the scheduler decided);
  actual vs onset:    the sequencer's "started" event (what the robot did): the 50 Hz tick grid adds
                      0..20 ms, and a gesture whose predecessor is still running waits for it to end
                      (plus the <= 0.3 s blend), which no schedule can undo.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from pathlib import Path

from emopose.clock import FakeClock
from emopose.context import RunContext
from emopose.jobs.report import markdown_table, write_results
from emopose.jobs.sync_measure import GestureSync, SuiteItem, load_suite, measure_turn, summarize
from emopose.stages.dispatch import Dispatch
from emopose.stages.schedule import ScheduleStage
from emopose.stages.sequence import SequenceStage

log = logging.getLogger(__name__)


@dataclass
class SyncEvalJob:
    suite: str
    fallback_suite: str | None = None
    modes: list[str] = field(default_factory=lambda: ["anchor", "words"])
    limit: int | None = None
    target_p95_ms: float = 60.0  # words mode, scheduled vs onset

    def __call__(self, ctx: RunContext) -> dict:
        if not hasattr(ctx.speech, "word_events"):
            raise ValueError(f"sync_eval measures against the engine's own word events, but tts is "
                             f"{getattr(ctx.speech, 'name', ctx.speech)!r}: run it with tts=espeak")
        if not isinstance(ctx.clock, FakeClock):
            raise ValueError("sync_eval runs on virtual time: use backend=dry_run with run.clock=auto")
        suite_path, items = self._items()
        ctx.open()
        rows: dict[str, list[GestureSync]] = {}
        for mode in self.modes:
            stages = self._stages(ctx, mode)
            rows[mode] = [row for item in items for row in self._run_item(ctx, stages, item)]
        results = self._results(ctx, suite_path, items, rows)
        write_results(ctx.run_dir, results, self._markdown(results))
        print(self._markdown(results))
        return results

    def _items(self) -> tuple[Path, list[SuiteItem]]:
        path = Path(self.suite)
        if not path.exists():
            if not self.fallback_suite:
                raise FileNotFoundError(f"job.suite {path} does not exist (set job.suite or job.fallback_suite)")
            log.warning("sequence suite %s is missing; measuring the fixture %s instead", path, self.fallback_suite)
            path = Path(self.fallback_suite)
        return path, load_suite(path, self.limit)

    def _stages(self, ctx: RunContext, mode: str) -> list:
        configured = {s.name: s for s in ctx.pipeline.stages}
        missing = [n for n in ("resolve", "modulate", "dispatch") if n not in configured]
        if missing:
            raise ValueError(f"sync_eval needs pipeline stages {missing}; pipeline has {list(configured)}")
        # Each item must start from rest with an empty queue, so dispatch waits for the neutral recovery.
        dispatch = Dispatch(timeout_s=configured["dispatch"].timeout_s, until="rest")
        return [configured["resolve"], configured["modulate"], ScheduleStage(mode=mode),
                SequenceStage(interrupt=False), dispatch]

    def _run_item(self, ctx: RunContext, stages: list, item: SuiteItem) -> list[GestureSync]:
        turn = ctx.new_turn(item.text, use_history=False)
        turn.values["plan"] = item.plan()
        for stage in stages:
            turn.values[stage.writes] = stage(turn, ctx)
        if not turn.dispatched.completed:
            log.warning("item %s did not come to rest within the dispatch timeout", item.id)
        return measure_turn(item, turn, ctx.speech.word_events(item.text))

    def _results(self, ctx: RunContext, suite_path: Path, items: list[SuiteItem], rows: dict) -> dict:
        summaries = {mode: summarize(r) for mode, r in rows.items()}
        missing = [{"item": r.item, "k": r.k, "trigger": r.trigger}
                   for r in next(iter(rows.values()), []) if not r.found]
        for m in missing:
            log.warning("say-do check: item %s record %d trigger %r is not in the reply", m["item"], m["k"], m["trigger"])
        words_p95 = summaries.get("words", {}).get("scheduled_vs_onset", {}).get("p95_abs_ms")
        speech = ctx.speech
        return {
            "suite": str(suite_path), "items": len(items),
            "tts": {"engine": speech.name, "voice": getattr(speech, "voice", None), "rate": getattr(speech, "rate", None)},
            "control_dt_s": ctx.loop.dt, "modes": summaries,
            "target": {"words_p95_scheduled_vs_onset_ms": self.target_p95_ms, "value_ms": words_p95,
                       "met": words_p95 is not None and words_p95 <= self.target_p95_ms},
            "say_do": {"missing": len(missing), "records": missing},
            "gestures": {mode: [r.as_json() for r in mode_rows] for mode, mode_rows in rows.items()},
        }

    @staticmethod
    def _markdown(results: dict) -> str:
        def ms(stats: dict, key: str) -> str:
            return "-" if stats[key] is None else f"{stats[key]:.0f}"

        header = ["mode", "gestures", "measured", "scheduled-onset mean abs (ms)", "p95", "mean signed",
                  "actual-onset mean abs (ms)", "p95", "p95 unqueued", "queued", "queue delay mean (ms)",
                  "scheduled-center p95 (ms)"]
        rows = []
        for mode, s in results["modes"].items():
            sched, actual, unq = s["scheduled_vs_onset"], s["actual_vs_onset"], s["actual_vs_onset_unqueued"]
            rows.append([mode, s["gestures"], s["measured"], ms(sched, "mean_abs_ms"), ms(sched, "p95_abs_ms"),
                         ms(sched, "mean_signed_ms"), ms(actual, "mean_abs_ms"), ms(actual, "p95_abs_ms"),
                         ms(unq, "p95_abs_ms"), s["queued"], ms(s["queue_delay"], "mean_abs_ms"),
                         ms(s["scheduled_vs_center"], "p95_abs_ms")])
        target = results["target"]
        say_do = results["say_do"]
        flagged = ", ".join(f"{m['item']}#{m['k']} {m['trigger']!r}" for m in say_do["records"]) or "none"
        return (f"# Speech-gesture sync ({results['items']} items from {results['suite']})\n\n"
                f"True onsets: {results['tts']['engine']} word events (voice {results['tts']['voice']}, "
                f"rate {results['tts']['rate']} wpm).\n\n{markdown_table(header, rows)}\n\n"
                f"Target: words-mode p95 |scheduled - onset| <= {target['words_p95_scheduled_vs_onset_ms']:.0f} ms: "
                f"{'met' if target['met'] else 'NOT met'} ({target['value_ms']}).\n\n"
                f"Say-do check: {say_do['missing']} record(s) whose trigger is not in the reply: {flagged}.\n\n"
                "scheduled vs onset is the scheduler's error; actual vs onset adds what execution does: the "
                "sequencer releases only on 50 Hz ticks (0-20 ms later), and a gesture whose predecessor is still "
                "running starts only after it ends plus the <= 0.3 s blend (\"queued\"); unqueued p95 leaves those out. "
                "The anchor equation aims at the phrase center, not its onset; scheduled-center shows its error "
                "against that target (center: midway between the phrase onset and the next word's onset).\n")
