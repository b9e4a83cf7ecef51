"""Real-time scheduling of the loop thread and its process: asked for, refused, and the fallbacks."""

from __future__ import annotations

import logging
import os
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from emopose.build import ConfigError, build_job
from emopose.child_process import ChildProcess
from emopose.execution import priority


def refuse(*_args) -> None:
    raise PermissionError("Operation not permitted")


def test_the_loop_thread_asks_for_sched_fifo_first(monkeypatch):
    calls = []
    monkeypatch.setattr(priority.os, "sched_setscheduler", lambda *args: calls.append(args))
    assert priority.raise_thread_priority(10) == "SCHED_FIFO 10"
    (thread, policy, param), = calls
    assert thread == threading.get_native_id() and policy == os.SCHED_FIFO and param.sched_priority == 10


def test_without_sched_fifo_the_thread_is_reniced_and_without_that_left_alone(monkeypatch, caplog):
    reniced = []
    monkeypatch.setattr(priority.os, "sched_setscheduler", refuse)
    monkeypatch.setattr(priority.os, "setpriority", lambda *args: reniced.append(args))
    assert priority.raise_thread_priority(10) == f"nice {priority.FALLBACK_NICE}"
    assert reniced == [(os.PRIO_PROCESS, threading.get_native_id(), priority.FALLBACK_NICE)]
    monkeypatch.setattr(priority.os, "setpriority", refuse)
    with caplog.at_level(logging.WARNING, logger=priority.__name__):
        assert priority.raise_thread_priority(10) == "normal"
    assert len(caplog.records) == 1 and "not permitted" in caplog.records[0].getMessage()


def test_every_thread_of_the_process_goes_below_the_loop_in_sched_rr(monkeypatch):
    """A thread holding the GIL the loop waits for must not be preempted by other processes' work."""
    asked = []
    monkeypatch.setattr(priority.os, "sched_setscheduler", lambda *args: asked.append(args))
    assert priority.raise_process_priority() == f"process SCHED_RR {priority.PROCESS_RT_PRIORITY}"
    threads = {int(task) for task in os.listdir("/proc/self/task")}
    assert {tid for tid, _, _ in asked} == threads and threading.get_native_id() in threads
    assert {(policy, param.sched_priority) for _, policy, param in asked} == {
        (os.SCHED_RR, priority.PROCESS_RT_PRIORITY)}


def test_without_sched_rr_the_process_is_reniced_and_without_that_left_alone(monkeypatch, caplog):
    reniced = []
    monkeypatch.setattr(priority.os, "sched_setscheduler", refuse)
    monkeypatch.setattr(priority.os, "setpriority", lambda *args: reniced.append(args))
    assert priority.raise_process_priority() == f"process nice {priority.PROCESS_NICE}"
    threads = {int(task) for task in os.listdir("/proc/self/task")}
    assert {tid for _, tid, _ in reniced} == threads
    assert {(kind, nice) for kind, _, nice in reniced} == {(os.PRIO_PROCESS, priority.PROCESS_NICE)}
    monkeypatch.setattr(priority.os, "setpriority", refuse)
    with caplog.at_level(logging.WARNING, logger=priority.__name__):
        assert priority.raise_process_priority() == "process nice unchanged"
    assert "not permitted" in caplog.records[0].getMessage()


def test_normal_scheduling_lowers_only_real_time_threads(monkeypatch):
    policies = {tid: os.SCHED_OTHER for tid in map(int, os.listdir("/proc/self/task"))}
    me = threading.get_native_id()
    policies[me] = os.SCHED_RR
    lowered = []
    monkeypatch.setattr(priority.os, "sched_getscheduler", policies.__getitem__)
    monkeypatch.setattr(priority.os, "sched_setscheduler", lambda *args: lowered.append(args[:2]))
    priority.normal_scheduling()
    assert lowered == [(me, os.SCHED_OTHER)]


def test_the_loop_must_rank_above_the_process(compose):
    with pytest.raises(ConfigError, match=r"run.rt_priority=1: the loop must rank above"):
        build_job(compose("+experiment=serve", "run.rt_priority=1"))


def write_policy(path: str) -> None:
    """Run in a ChildProcess: its scheduling policy, to a file."""
    Path(path).write_text(str(os.sched_getscheduler(0)))


def test_a_child_process_of_a_real_time_process_starts_at_normal_scheduling(tmp_path):
    try:
        os.sched_setscheduler(0, os.SCHED_RR, os.sched_param(priority.PROCESS_RT_PRIORITY))
    except PermissionError:
        pytest.skip("real-time scheduling not permitted here")
    try:
        child = ChildProcess("tests.core.test_priority", "write_policy", str(tmp_path / "policy"))
        inherited = subprocess.run([sys.executable, "-c", "import os; print(os.sched_getscheduler(0))"],
                                   capture_output=True, text=True, check=True)
    finally:
        os.sched_setscheduler(0, os.SCHED_OTHER, os.sched_param(0))
    assert child.process.wait(timeout=60) == 0
    assert int(inherited.stdout) == os.SCHED_RR  # what a child gets without the reset
    assert int((tmp_path / "policy").read_text()) == os.SCHED_OTHER
