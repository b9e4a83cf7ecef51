"""Worker: the one start/stop skeleton of the project's background threads."""

from __future__ import annotations

import threading

from emopose.execution.worker import Worker


def test_runs_until_stopped_and_can_start_again():
    laps = []

    def loop(stop: threading.Event) -> None:
        while not stop.wait(0.001):
            laps.append(threading.current_thread().name)

    def run_a_lap() -> None:
        before = len(laps)
        while len(laps) == before:
            threading.Event().wait(0.001)

    worker = Worker("test-worker", loop, join_timeout_s=2.0)
    worker.start()
    worker.start()  # already running: no second thread
    run_a_lap()
    assert worker.running and sum(t.name == "test-worker" for t in threading.enumerate()) == 1
    worker.stop()
    assert not worker.running and set(laps) == {"test-worker"}
    worker.start()
    run_a_lap()
    worker.stop()
    worker.stop()  # twice is safe
    assert not worker.running


def test_stop_from_its_own_thread_does_not_wait_for_itself():
    done = threading.Event()

    def loop(stop: threading.Event) -> None:
        worker.stop()  # a fault handler tearing its owner down
        done.set()

    worker = Worker("self-stopping", loop, join_timeout_s=30.0)
    worker.start()
    assert done.wait(2.0)
