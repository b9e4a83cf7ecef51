"""+experiment=g1_check: connect to the G1, read its state, run one gesture gently, release, report.

The hand-over is the backend's: connect() refuses to start without fresh rt/lowstate and ramps the
arm_sdk weight up while holding the measured pose; closing the session blends to neutral and ramps
the weight down. The gesture goes through the normal resolve..dispatch stages at low intensity.
A fault (no robot, lost state, a stalled stream) is a result too, as in every job
(emopose/jobs/robot_fault.py): results.json/results.md say what happened and when, and the process
exits 3 with one line, not a traceback. Event times are seconds since the run started (the session's
open, the recording's zero).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from emopose.contract import EventKind, GestureRecord, Plan
from emopose.resources import Run
from emopose.results import JobOutput


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
                   "fault": None}
        session.open()
        measured = res.backend.measured()
        results["measured_start"] = np.asarray(measured).tolist()
        print(f"connected to {res.backend.name}; measured arm pose (rad): {np.round(measured, 3).tolist()}")
        record = GestureRecord(cls=entry.cls, variant=entry.name, intensity=self.intensity)
        turn = run.runner.run_plan(Plan.scripted(f"g1 check: {self.gesture}", record))
        results["completed"] = turn.dispatched.completed
        results["events"] = [(e.kind, e.name, round(session.run_time(e.t), 3))
                             for e in events.since(first_event) if e.kind != EventKind.STATE]
        results["loop"] = session.loop.stats.summary()
        return results, self._markdown(results)

    def _markdown(self, r: dict) -> str:
        return "\n".join([
            f"# g1_check on {r['backend']}", f"- start pose: {np.round(r['measured_start'], 3).tolist()}",
            f"- gesture {r['gesture']} at intensity {r['intensity']}: "
            f"{'completed' if r['completed'] else 'NOT completed'}",
            f"- events (s since the run started): {r['events']}", f"- 50 Hz loop: {r['loop']}",
            "- release: blend to neutral, weight ramp to 0 (on exit)"])
