"""Scheduling for real-time loops: the loop thread first (SCHED_FIFO, else a negative nice, else as it was,
with one log line), the process's other threads raised a little, and run.rt_priority checked."""

from __future__ import annotations

import contextlib
import logging
import os
import threading

log = logging.getLogger(__name__)

FALLBACK_NICE = -10  # where SCHED_FIFO is refused but raising the thread's nice value is allowed
# The process's other threads (web server, planner, speech) in real-time runs. The loop thread needs the
# GIL on every tick, so a thread holding it that the OS preempts for other processes' work holds the loop
# up as long (priority inversion through the GIL). At any nice value that happened: 100-340 ms late ticks
# with three busy processes, nice -5 or -20 alike; in SCHED_RR below the loop, none over 20 ms
# (benchmarks/loop_under_load.py). Real-time threads can starve normal work while they compute; Linux
# keeps 5 % of each CPU for it (sched_rt_runtime_us), and run.rt_priority=0 leaves all of this off.
PROCESS_RT_PRIORITY = 1
PROCESS_NICE = -5  # where SCHED_RR is refused


def check_rt_priority(priority: int) -> int:
    """run.rt_priority, checked where a job is configured: the OS would refuse a value outside 1-99 and the
    loop would fall back unnoticed."""
    if not 0 <= priority <= 99:
        raise ValueError(f"run.rt_priority={priority}: a SCHED_FIFO priority is 1-99 (0: normal)")
    if priority == PROCESS_RT_PRIORITY:
        raise ValueError(f"run.rt_priority={priority}: the loop must rank above the process's other threads "
                         f"(SCHED_RR {PROCESS_RT_PRIORITY}): use 2-99")
    return priority


def raise_thread_priority(priority: int) -> str:
    """Ask the OS to run the calling thread first: SCHED_FIFO at `priority` (1-99), else nice
    FALLBACK_NICE. Where neither is permitted (no CAP_SYS_NICE, a container, not Linux) the thread keeps
    its scheduling and one log line says so. Returns what the thread got."""
    thread = threading.get_native_id()
    try:
        os.sched_setscheduler(thread, os.SCHED_FIFO, os.sched_param(priority))
        return f"SCHED_FIFO {priority}"
    except (AttributeError, OSError):
        pass
    try:
        os.setpriority(os.PRIO_PROCESS, thread, FALLBACK_NICE)  # Linux: a thread id sets that thread only
        return f"nice {FALLBACK_NICE}"
    except (AttributeError, OSError) as exc:
        log.warning("control loop: real-time priority not permitted (%s); normal scheduling", exc)
        return "normal"


def _threads() -> list[int]:
    return [int(task) for task in os.listdir("/proc/self/task")]  # Linux: scheduling is per thread


def raise_process_priority() -> str:
    """Every thread of this process (and those it starts later: they inherit it) in SCHED_RR at
    PROCESS_RT_PRIORITY, else at nice PROCESS_NICE, else as it was (one log line). Returns what they got.
    Child processes inherit it too: ChildProcess children drop it (normal_scheduling) as they start."""
    try:
        for thread in _threads():
            os.sched_setscheduler(thread, os.SCHED_RR, os.sched_param(PROCESS_RT_PRIORITY))
        return f"process SCHED_RR {PROCESS_RT_PRIORITY}"
    except (AttributeError, OSError):
        pass
    try:
        for thread in _threads():
            os.setpriority(os.PRIO_PROCESS, thread, PROCESS_NICE)
        return f"process nice {PROCESS_NICE}"
    except (AttributeError, OSError) as exc:
        log.warning("control loop: raising the process's priority not permitted (%s)", exc)
        return "process nice unchanged"


def normal_scheduling() -> None:
    """Every real-time thread of this process back at normal scheduling (lowering is always permitted):
    when a real-time run's loop stops, and in a child of a real-time process as it starts."""
    for thread in _threads():
        with contextlib.suppress(AttributeError, OSError):  # a thread may end meanwhile
            if os.sched_getscheduler(thread) in (os.SCHED_RR, os.SCHED_FIFO):
                os.sched_setscheduler(thread, os.SCHED_OTHER, os.sched_param(0))
