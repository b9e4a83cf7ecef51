"""+experiment=plan: run one utterance through the whole pipeline and show every step."""

from __future__ import annotations

from dataclasses import dataclass

from emopose.contract import EventKind
from emopose.resources import Run
from emopose.results import JobOutput, markdown_table


@dataclass
class PlanJob:
    utterance: str
    image: str | None = None

    def __post_init__(self) -> None:  # checked when the job is built: a config error, before anything starts
        if not self.utterance.strip():
            raise ValueError("utterance is empty: pass utterance=\"...\"")

    def __call__(self, run: Run) -> JobOutput:
        res = run.resources
        turn = run.runner.run(self.utterance, self.image)
        recorder = run.session.recorder
        rows = []
        for resolved, release in zip(turn.resolved, turn.schedule.releases):
            r = resolved.record
            rows.append([r.cls, r.variant or "-", resolved.entry.name, resolved.rule, r.intensity,
                         r.trigger or "-", f"{release.release_s:.2f} s ({release.how})"])
        table = markdown_table(["class", "requested", "resolved", "rule", "intensity", "trigger", "release"],
                               rows)
        started = [e for e in turn.dispatched.events if e.kind == EventKind.STARTED]
        data = turn.to_json()
        results = {
            "utterance": self.utterance,
            "planner": res.planner.name,
            "reply": data["plan"]["reply"],
            "plan_source": data["plan"]["source"],
            "records": data["plan"]["records"],
            "resolved": data["resolved"],
            "releases_s": [r["release_s"] for r in data["schedule"]["releases"]],
            "speech_duration_s": data["speech"]["duration_s"],
            "executed": [{"name": e.name, "t": e.t} for e in started],
            "completed": turn.dispatched.completed,
            "mcap": str(recorder.path) if recorder else None,
            "stage_ms": data["stage_ms"],
            "loop": run.session.loop.stats.summary(),  # missed deadlines, stalls, lateness (real time)
            "turn": data,  # every value of the turn, as the MCAP recording holds it
        }
        text = (f"Utterance: {self.utterance}\nReply: {turn.plan.reply}  (plan from {turn.plan.source}, "
                f"planner {res.planner.name})\n\n{table}\n\nSpeech {turn.speech.duration_s:.2f} s; "
                f"{len(started)} gesture(s) executed on {res.backend.name}; "
                f"recording: {results['mcap']}")
        return results, text
