"""A fault on the robot ends every job the same way: as a result, not a traceback.

A fault is the G1 backend refusing or giving up (no robot, lost rt/lowstate, the deadman, the connection
dropped: G1BackendError, the arms already handed back) or the robot's loco service failing (LocoError,
LocoTimeoutError), raised anywhere in the job, also wrapped (the control loop's thread reports its error
as the cause of its own). emopose.app turns it into results.json / results.md (the job and its settings,
the fault and when it happened in seconds since the run started, the sequencer's events, the loop's
counters, the recording) and raises RobotFault: `python -m emopose` prints its one line and exits
ROBOT_FAULT_EXIT (3).
"""

from __future__ import annotations

import dataclasses

from emopose.backends.g1.errors import G1BackendError, LocoError, LocoTimeoutError
from emopose.contract import EventKind
from emopose.resources import Run
from emopose.results import JobFailure

ROBOT_FAULT_EXIT = 3
FAULTS = (G1BackendError, LocoError, LocoTimeoutError)


class RobotFault(Exception):
    """The job ended on a robot fault; its results are written. The message is one line."""


def fault_behind(error: BaseException) -> BaseException | None:
    """The robot fault `error` is, or was raised from (its causes and contexts), if any."""
    seen: set[int] = set()
    while error is not None and id(error) not in seen:
        if isinstance(error, FAULTS):
            return error
        seen.add(id(error))
        error = error.__cause__ or error.__context__
    return None


def fault_failure(run: Run, job: object, error: BaseException) -> JobFailure | None:
    """The job's results for a robot fault behind `error` (None: it is no robot fault)."""
    fault = fault_behind(error)
    if fault is None:
        return None
    res, session = run.resources, run.session
    name = type(job).__name__
    at = None if session.origin is None else round(session.run_time(res.clock.now()), 3)
    reason = " ".join(str(fault).split())
    settings = dataclasses.asdict(job) if dataclasses.is_dataclass(job) else {}
    recorder = session.recorder
    events = [(e.kind, e.name, round(session.run_time(e.t), 3))
              for e in res.sequencer.events.since(0) if e.kind != EventKind.STATE]
    results = {"job": name, **settings, "backend": res.backend.name, "completed": False, "fault": reason,
               "fault_at_s": at, "events": events, "loop": session.loop.stats.summary(),
               "mcap": str(recorder.path) if recorder else None}
    markdown = "\n".join([f"# {name} on {res.backend.name}: FAULT at {at} s", "", reason, "",
                          f"- events (s since the run started): {results['events']}",
                          f"- 50 Hz loop: {results['loop']}", f"- recording: {results['mcap'] or 'none'}",
                          "- the arms: handed back to the firmware (or never taken, for a fault at connect)"])
    return JobFailure(results, markdown, RobotFault(f"{name}: robot FAULT at {at} s: {reason} "
                                                    f"(results in {res.run_dir})"))
