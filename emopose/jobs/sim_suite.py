"""+experiment=sim_suite: the paper's MuJoCo protocol (Simulation and Physical-G1 Evaluation).

Class-balanced trials, each the class default at one intensity (level 3), run through the real
pipeline (parse -> resolve -> modulate -> schedule -> sequence -> dispatch until=settle) on the
configured backend with the control loop's virtual clock; physics advances in send(), so trial time
and simulated time agree. A session does not reset the robot between utterances: each trial starts
where the previous one left the arms (its held end pose), or, on alternate trials, after the
sequencer's own 2 s hold + 1 s recovery to neutral. Completion = a "completed" event for the trial's
command without a stop request, a safety rejection or a dispatch timeout. Tracking per
emopose/jobs/tracking.py (tick alignment, N resampled points, Eq. sim-MAE). With `compare_law` the
same trials run again with the simulator's servos under that arm law (the MJCF's own, say), so the
results show how much the configured law (the robot's, by default) costs in tracking.
"""

from __future__ import annotations

import json
import logging
from dataclasses import dataclass

import numpy as np

from emopose import CLASSES
from emopose.backends.capabilities import SimulatedState
from emopose.backends.stream_tap import StreamTap
from emopose.contract import EventKind, GestureRecord, Plan
from emopose.execution.gesture_command import State
from emopose.jobs.sim_report import suite_markdown
from emopose.jobs.tracking import latency_ms, sim_mae, tracking_error
from emopose.resources import Run
from emopose.results import JobOutput
from emopose.robot.arm_law import ArmLaw

log = logging.getLogger(__name__)
START_MODES = ("alternate", "previous", "rest")


@dataclass
class SimSuiteJob:
    trials: int = 160
    intensity: int = 3
    start_from: str = "alternate"  # alternate | previous (held end pose) | rest (after neutral recovery)
    points: int = 100
    seed: int = 0
    rest_timeout_s: float = 10.0
    compare_law: ArmLaw | None = None

    def __post_init__(self) -> None:
        if self.trials < len(CLASSES) or self.trials % len(CLASSES):
            raise ValueError(f"sim_suite: trials must be a positive multiple of {len(CLASSES)} "
                             f"(class-balanced), got {self.trials}")
        if self.start_from not in START_MODES:
            raise ValueError(f"sim_suite: start_from must be one of {START_MODES}, got {self.start_from!r}")
        if not 1 <= self.intensity <= 5:
            raise ValueError(f"sim_suite: intensity must be 1..5, got {self.intensity}")

    def __call__(self, run: Run) -> JobOutput:
        res = run.resources
        motions = {c: res.library.class_default(c) for c in CLASSES}
        missing = [c for c, m in motions.items() if m is None]
        if missing:
            raise ValueError(f"sim_suite: library has no motion for classes {missing}")
        order = np.random.default_rng(self.seed).permutation(
            np.repeat(np.array(CLASSES), self.trials // len(CLASSES)))
        loop = run.session.open()
        tap = run.session.tap(StreamTap)  # capture command/state pairs in memory, tick by tick
        t0 = res.clock.now() - loop.stream_time
        rows = [self._trial(run, tap, t0, k, str(cls), motions[str(cls)].name) for k, cls in enumerate(order)]
        results = self._summarise(run, rows)
        simulator = res.backend if isinstance(res.backend, SimulatedState) else None
        results["arm_law"] = None if simulator is None else simulator.law.name
        if simulator is not None and self.compare_law is not None:
            results["compare"] = self._under(run, tap, t0, order, motions, simulator, self.compare_law)
        (res.run_dir / "trials.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
        return results, suite_markdown(results)

    def _under(self, run: Run, tap: StreamTap, t0: float, order, motions, simulator, law: ArmLaw) -> dict:
        """The same trials with the servos under `law`; the configured law is restored after."""
        configured = simulator.law
        simulator.apply_law(law)
        try:
            rows = [self._trial(run, tap, t0, k, str(cls), motions[str(cls)].name)
                    for k, cls in enumerate(order)]
        finally:
            simulator.apply_law(configured)
        summary = self._summarise(run, rows)
        keys = ("completed", "mae_rad", "mae_deg", "per_class_mae_rad", "mae_time_aligned_rad",
                "max_abs_error_rad")
        return {"arm_law": law.name, **{k: summary[k] for k in keys}}

    def _start_mode(self, k: int) -> str:
        if self.start_from == "alternate":
            return "rest" if k % 2 else "previous"
        return self.start_from

    def _trial(self, run: Run, tap: StreamTap, t0: float, k: int, cls: str, motion: str) -> dict:
        loop, sequencer = run.session.loop, run.resources.sequencer
        start = self._start_mode(k)
        if start == "rest":
            loop.run_until(lambda: sequencer.state == State.IDLE, self.rest_timeout_s)
        q_start = sequencer.last.copy()
        first_tick, first_build = len(tap), sequencer.construction_s.total
        simulated = tap.backend if isinstance(tap.backend, SimulatedState) else None
        if simulated is not None:
            simulated.max_actuator_force_ratio = 0.0  # per-trial peak
        record = GestureRecord(cls=cls, variant=motion, intensity=self.intensity)
        turn = run.runner.run_plan(Plan.scripted(f"Trial {k}.", record), utterance=f"sim trial {k}: {cls}")
        report, command = turn.dispatched, turn.submitted.commands[0]
        mine = [e for e in report.events if e.command_id == command.id]
        kinds = {e.kind for e in mine}
        row = {"trial": k, "class": cls, "motion": turn.resolved[0].entry.name, "start": start,
               "start_offset_rad": float(np.max(np.abs(q_start - command.keyframes[0]))),
               "completed": (EventKind.COMPLETED in kinds
                             and not kinds & {EventKind.STOPPED, EventKind.REJECTED}
                             and report.completed),
               "stopped": EventKind.STOPPED in kinds, "rejected": EventKind.REJECTED in kinds,
               "timeout": not report.completed,
               "construction_s": sequencer.construction_s.since(first_build),
               "submission_s": list(turn.submitted.submission_s)}
        row["force_ratio"] = simulated.max_actuator_force_ratio if simulated is not None else float("nan")
        started = next((e for e in mine if e.kind == EventKind.STARTED), None)
        done = next((e for e in mine if e.kind == EventKind.COMPLETED), None)
        if started is None or done is None:
            log.warning("trial %d (%s) did not complete: %s", k, cls, sorted(kinds))
            return row
        a, b = tap.tick_at(started.t - t0, first_tick), tap.tick_at(done.t - t0, first_tick)
        commands, states = tap.window(a, b)
        error = tracking_error(commands, states, self.points)
        row.update(ticks=b - a + 1, duration_s=(b - a) * loop.dt, mae_rad=error.mae,
                   mae_time_aligned_rad=error.mae_time_aligned, max_abs_error_rad=error.max_abs,
                   contacts=sorted({f"{p[0]}|{p[1]}" for tick, _, p in tap.contacts if a <= tick <= b}))
        row["_error"] = error
        return row

    def _summarise(self, run: Run, rows: list[dict]) -> dict:
        res, recorder = run.resources, run.session.recorder
        errors = [r.pop("_error") for r in rows if "_error" in r]
        done = [r for r in rows if "mae_rad" in r]
        per_class, per_class_time, per_class_force = {}, {}, {}
        for cls in CLASSES:
            mine = [e for r, e in zip(done, errors) if r["class"] == cls]
            per_class[cls] = sim_mae(mine)
            per_class_time[cls] = sim_mae(mine, "time")
            per_class_force[cls] = max((r["force_ratio"] for r in rows if r["class"] == cls), default=0.0)
        contacts = [{"trial": r["trial"], "class": r["class"], "pair": p}
                    for r in done for p in r["contacts"]]
        mae = sim_mae(errors)
        return {
            "trials": len(rows),
            "completed": sum(r["completed"] for r in rows),
            "stops": sum(r["stopped"] for r in rows),
            "timeouts": sum(r["timeout"] for r in rows),
            "rejected": sum(r["rejected"] for r in rows),
            "mae_rad": mae,
            "mae_deg": float(np.degrees(mae)),
            "per_class_mae_rad": per_class,
            "mae_time_aligned_rad": sim_mae(errors, "time"),
            "per_class_mae_time_aligned_rad": per_class_time,
            "max_abs_error_rad": max((r["max_abs_error_rad"] for r in done), default=float("nan")),
            "max_actuator_force_ratio": max(per_class_force.values()),
            "per_class_max_actuator_force_ratio": per_class_force,
            "self_contacts": len(contacts),
            "self_contact_pairs": contacts[:50],
            "construction_ms": latency_ms([s for r in rows for s in r["construction_s"]]),
            "submission_ms": latency_ms([s for r in rows for s in r["submission_s"]]),
            "start_offset_rad": {
                m: float(np.mean([r["start_offset_rad"] for r in rows if r["start"] == m] or [0]))
                for m in ("previous", "rest")},
            "motions": {c: res.library.class_default(c).name for c in CLASSES},
            "intensity": self.intensity,
            "start_from": self.start_from,
            "points": self.points,
            "backend": res.backend.name,
            "dispatch_until": res.pipeline.get("dispatch").until,
            "alignment": "tick: command n vs simulated pose after tick n's physics (stamped t_n + 0.02 s); "
                         "time: that pose vs command n+1 issued at t_n + 0.02 s",
            "mcap": str(recorder.path) if recorder else None,
        }
