"""+experiment=g1_check: connect to the G1, read its state, run one gesture gently, release, report.

The hand-over is the backend's: connect() refuses to start without fresh rt/lowstate and ramps the
arm_sdk weight up while holding the measured pose; closing the session blends to neutral and ramps
the weight down. The gesture goes through the normal resolve..dispatch stages at low intensity.
A fault (no robot, lost state, a stalled stream) is a result too: results.json/results.md say what
happened and when, and the process exits non-zero with one line, not a traceback. Event times are
seconds since the run started (the session's open, the recording's zero).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from emopose.backends.g1.errors import G1BackendError
from emopose.contract import EventKind, GestureRecord, Plan
from emopose.resources import Run
from emopose.results import JobFailure, JobOutput


@dataclass
class G1CheckJob:
    gesture: str = "face_wave"
    intensity: int = 1

    def __call__(self, run: Run) -> JobOutput:
        res, session = run.resources, run.session
        entry = res.library.get(self.gesture)
        if entry is None:
            raise ValueError(f"g1_check: no motion '{self.gesture}' in the library (job.gesture)")
        events = res.sequencer.events
        first_event = events.total
        results = {"backend": res.backend.name, "gesture": self.gesture, "intensity": self.intensity,
                   "completed": False, "fault": None, "fault_at_s": None, "measured_start": None}
        try:
            session.open()
            measured = res.backend.measured()
            results["measured_start"] = np.asarray(measured).tolist()
            print(f"connected to {res.backend.name}; measured arm pose (rad): "
                  f"{np.round(measured, 3).tolist()}")
            record = GestureRecord(cls=entry.cls, variant=entry.name, intensity=self.intensity)
            turn = run.runner.run_plan(Plan.scripted(f"g1 check: {self.gesture}", record))
            results["completed"] = turn.dispatched.completed
        except G1BackendError as exc:
            results["fault"] = str(exc)
            if session.origin is not None:
                results["fault_at_s"] = round(session.run_time(res.clock.now()), 3)
        results["events"] = [(e.kind, e.name, round(session.run_time(e.t), 3))
                             for e in events.since(first_event) if e.kind != EventKind.STATE]
        results["loop"] = session.loop.stats.summary()
        if results["fault"] is not None:  # written, then the process exits non-zero with one line
            raise JobFailure(results, self._markdown(results), SystemExit(
                f"g1_check: FAULT at {results['fault_at_s']} s: {results['fault']} "
                f"(results in {res.run_dir})"))
        return results, self._markdown(results)

    def _markdown(self, r: dict) -> str:
        measured = r["measured_start"]
        start = np.round(measured, 3).tolist() if measured is not None else "not measured"
        outcome = ("completed" if r["completed"] else "NOT completed") if r["fault"] is None else \
            f"FAULT at {r['fault_at_s']} s: {r['fault']}"
        return "\n".join([
            f"# g1_check on {r['backend']}", f"- start pose: {start}",
            f"- gesture {r['gesture']} at intensity {r['intensity']}: {outcome}",
            f"- events (s since the run started): {r['events']}", f"- 50 Hz loop: {r['loop']}",
            "- release: blend to neutral, weight ramp to 0 (on exit)"])
