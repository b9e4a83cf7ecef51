"""+experiment=plan: run one utterance through the whole pipeline and show every step."""

from __future__ import annotations

from dataclasses import dataclass

from emopose.context import RunContext
from emopose.jobs.report import markdown_table, write_results


@dataclass
class PlanJob:
    utterance: str
    image: str | None = None

    def __call__(self, ctx: RunContext) -> dict:
        if not self.utterance.strip():
            raise ValueError("utterance is empty: pass utterance=\"...\"")
        turn = ctx.run_turn(self.utterance, self.image)
        rows = []
        for resolved, release in zip(turn.resolved, turn.schedule.releases):
            r = resolved.record
            rows.append([r.cls, r.variant or "-", resolved.entry.name, resolved.rule, r.intensity,
                         r.trigger or "-", f"{release.release_s:.2f} s ({release.how})"])
        table = markdown_table(["class", "requested", "resolved", "rule", "intensity", "trigger", "release"], rows)
        started = [e for e in turn.dispatched.events if e.kind == "started"]
        results = {
            "utterance": self.utterance,
            "planner": ctx.planner.name,
            "reply": turn.plan.reply,
            "plan_source": turn.plan.source,
            "records": [r.as_json() for r in turn.plan.records],
            "resolved": [r.audit() for r in turn.resolved],
            "releases_s": [r.release_s for r in turn.schedule.releases],
            "speech_duration_s": turn.schedule.speech.duration_s,
            "executed": [{"name": e.name, "t": e.t} for e in started],
            "completed": turn.dispatched.completed,
            "mcap": str(ctx.recorder.path) if ctx.recorder else None,
            "stage_ms": {k: v * 1e3 for k, v in turn.stage_s.items()},
        }
        text = (f"Utterance: {self.utterance}\nReply: {turn.plan.reply}  (plan from {turn.plan.source}, "
                f"planner {ctx.planner.name})\n\n{table}\n\nSpeech {turn.schedule.speech.duration_s:.2f} s; "
                f"{len(started)} gesture(s) executed on {ctx.backend.name}; "
                f"recording: {results['mcap']}")
        write_results(ctx.run_dir, results, text)
        print(text)
        return results
