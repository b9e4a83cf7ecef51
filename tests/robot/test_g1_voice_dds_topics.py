"""DDS topics are created one at a time in a process (#33): cyclonedds fills a type's XTypes data lazily on
its first Topic and not thread-safely, and serve's chest light (its first request, on its worker) created
its topics while the backend's connect created its own: an AttributeError inside cyclonedds or a crash.
Counted with a stand-in Topic that holds each creation open; no timing is asserted."""

from __future__ import annotations

import threading
import time

from tests.backends.g1.conftest import require_dds


def test_two_threads_never_create_topics_at_the_same_time(monkeypatch):
    require_dds()
    from emopose.backends.g1 import dds

    inside, most = [0], [0]
    lock = threading.Lock()

    class HeldTopic:
        def __init__(self, participant, name: str, data_type: type) -> None:
            with lock:
                inside[0] += 1
                most[0] = max(most[0], inside[0])
            time.sleep(0.05)  # long enough for the other thread to arrive while this one is inside
            with lock:
                inside[0] -= 1

    monkeypatch.setattr(dds, "Topic", HeldTopic)
    sessions = [object.__new__(dds.DdsSession) for _ in range(2)]  # no participant: only _topic runs
    for session in sessions:
        session.participant, session._topics = None, {}
    start = threading.Barrier(2)

    def create(session, name: str) -> None:
        start.wait()
        for k in range(3):
            session._topic(f"{name}{k}", object)

    threads = [threading.Thread(target=create, args=(s, n)) for s, n in zip(sessions, ("light", "lowstate"))]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=10.0)
    assert most[0] == 1 and all(len(s._topics) == 3 for s in sessions)
    assert sessions[0]._topic("light0", object) is sessions[0]._topics["light0"]  # made once, then reused
