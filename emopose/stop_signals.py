"""Stopping a run from outside: SIGTERM (systemd, `docker stop`, `timeout`) is handled like Ctrl-C.

Python turns SIGINT into KeyboardInterrupt, but SIGTERM kills the process where it stands by default:
the robot is not handed back, the MCAP recording is left without its footer (unreadable) and no
results are written. Inside `sigterm_interrupts()` SIGTERM raises `Terminated` (a KeyboardInterrupt)
in the main thread instead, so every job unwinds through the one path Ctrl-C takes: uvicorn captures
both signals while it serves and shuts down gracefully, `with run:` stops the control loop, releases
the backend and closes the recorder, and app.run writes results. Only the first SIGTERM interrupts;
later ones are ignored so that the release in progress finishes (a supervisor escalates to SIGKILL).
"""

from __future__ import annotations

import contextlib
import logging
import signal
import threading
from collections.abc import Iterator

log = logging.getLogger(__name__)


class Terminated(KeyboardInterrupt):
    """Raised in the main thread by SIGTERM."""


def signal_name(interrupt: KeyboardInterrupt) -> str:
    return "SIGTERM" if isinstance(interrupt, Terminated) else "SIGINT"


def exit_status(interrupt: KeyboardInterrupt) -> int:
    """The shell's convention for a process ended by a signal: 128 + its number."""
    return 128 + (signal.SIGTERM if isinstance(interrupt, Terminated) else signal.SIGINT)


@contextlib.contextmanager
def sigterm_interrupts() -> Iterator[None]:
    """While inside, SIGTERM raises Terminated in the main thread (elsewhere: does nothing)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    received = []

    def on_sigterm(signum: int, frame: object) -> None:
        if received:
            log.warning("SIGTERM again: still releasing the robot and closing the recording")
            return
        received.append(signum)
        raise Terminated()

    previous = signal.signal(signal.SIGTERM, on_sigterm)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)
