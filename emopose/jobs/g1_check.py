"""+experiment=g1_check: connect to the G1, read its state, run one gesture gently, release, report.

The hand-over is the backend's: connect() refuses to start without fresh rt/lowstate and ramps the
arm_sdk weight up while holding the measured pose; closing the session blends to neutral and ramps
the weight down. The gesture goes through the normal resolve..dispatch stages at low intensity.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from emopose.contract import GestureRecord, Plan
from emopose.jobs.report import write_results
from emopose.resources import Run


@dataclass
class G1CheckJob:
    gesture: str = "face_wave"
    intensity: int = 1

    def __call__(self, run: Run) -> dict:
        res = run.resources
        entry = res.library.get(self.gesture)
        if entry is None:
            raise ValueError(f"g1_check: no motion '{self.gesture}' in the library (job.gesture)")
        loop = run.session.open()
        measured = res.backend.measured()
        print(f"connected to {res.backend.name}; measured arm pose (rad): {np.round(measured, 3).tolist()}")
        record = GestureRecord(cls=entry.cls, variant=entry.name, intensity=self.intensity)
        turn = run.runner.run_plan(Plan.scripted(f"g1 check: {self.gesture}", record))
        events = [(e.kind, e.name, round(e.t, 3)) for e in turn.dispatched.events if e.kind != "state"]
        stats = loop.stats.summary()
        results = {"backend": res.backend.name, "measured_start": np.asarray(measured).tolist(),
                   "gesture": self.gesture, "intensity": self.intensity, "completed": turn.dispatched.completed,
                   "events": events, "loop": stats}
        write_results(res.run_dir, results, "\n".join([
            f"# g1_check on {res.backend.name}", f"- start pose: {np.round(measured, 3).tolist()}",
            f"- gesture {self.gesture} at intensity {self.intensity}: "
            f"{'completed' if turn.dispatched.completed else 'NOT completed'}",
            f"- events: {events}", f"- 50 Hz loop: {stats}", "- release: blend to neutral, weight ramp to 0 (on exit)"]))
        print(f"ran {self.gesture} at intensity {self.intensity}: completed={turn.dispatched.completed}; "
              f"loop {stats}; releasing (blend to neutral, arm_sdk weight -> 0)")
        return results
