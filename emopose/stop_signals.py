"""Stopping a run from outside: SIGTERM (systemd, `docker stop`, `timeout`) is handled like Ctrl-C.

Python turns SIGINT into KeyboardInterrupt, but SIGTERM kills the process where it stands by default:
the robot is not handed back, the MCAP recording is left without its footer (unreadable) and no
results are written. Inside `stop_signals_interrupt()` SIGTERM raises `Terminated` (a KeyboardInterrupt)
in the main thread instead, so every job unwinds through the one path Ctrl-C takes: uvicorn captures
both signals while it serves and shuts down gracefully, `with run:` stops the control loop, releases
the backend and closes the recorder, and app.run writes results. Only the first SIGTERM interrupts;
later ones are ignored so that the release in progress finishes (a supervisor escalates to SIGKILL).

The interrupt a stop signal raised is also remembered (`stop_requested()`), because it does not always
arrive as itself: a library may swallow it (uvicorn.run returns normally after its graceful shutdown)
or wrap it (raised while ctypes converts a call's arguments, as in mujoco's EGL probing, it becomes a
ctypes.ArgumentError). app.run turns either back into the interrupt, so every job ends with the same
results and the same exit status: 143 after SIGTERM, 130 after SIGINT.

`python -m emopose` enters stop_signals_interrupt() before it imports anything else (emopose/__main__.py),
so this module imports only small standard modules (logging and what it pulls in, ~20 ms, only once a
second SIGTERM needs it): a signal during the seconds of imports after it is handled too, and the window
before it is the interpreter's start and a few ms (tests/test_main_imports.py).
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator

_requested: list[KeyboardInterrupt] = []  # the first stop signal's interrupt inside stop_signals_interrupt()


class Terminated(KeyboardInterrupt):
    """Raised in the main thread by SIGTERM."""


def signal_name(interrupt: KeyboardInterrupt) -> str:
    return "SIGTERM" if isinstance(interrupt, Terminated) else "SIGINT"


def exit_status(interrupt: KeyboardInterrupt) -> int:
    """The shell's convention for a process ended by a signal: 128 + its number."""
    return 128 + (signal.SIGTERM if isinstance(interrupt, Terminated) else signal.SIGINT)


def stop_requested() -> KeyboardInterrupt | None:
    """The interrupt the first SIGTERM or SIGINT raised inside stop_signals_interrupt(), even if a library
    swallowed or wrapped it; None when no stop signal came."""
    return _requested[0] if _requested else None


def interrupt_behind(error: BaseException) -> KeyboardInterrupt | None:
    """The interrupt that ended a run with `error`: the error itself, or the stop signal behind another
    error (a library that wrapped it); None for an error no stop signal caused."""
    return error if isinstance(error, KeyboardInterrupt) else stop_requested()


@contextlib.contextmanager
def stop_signals_interrupt() -> Iterator[None]:
    """While inside, SIGTERM raises Terminated and SIGINT KeyboardInterrupt in the main thread, and the
    first is remembered (elsewhere: does nothing)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    _requested.clear()
    terminated = []

    def on_sigterm(signum: int, frame: object) -> None:
        if terminated:
            import logging  # here, not at the top: see the module's last paragraph

            logging.getLogger(__name__).warning(
                "SIGTERM again: still releasing the robot and closing the recording")
            return
        terminated.append(signum)
        raise _remember(Terminated())

    def on_sigint(signum: int, frame: object) -> None:
        raise _remember(KeyboardInterrupt())

    previous = {signal.SIGTERM: signal.signal(signal.SIGTERM, on_sigterm),
                signal.SIGINT: signal.signal(signal.SIGINT, on_sigint)}
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        _requested.clear()


def _remember(interrupt: KeyboardInterrupt) -> KeyboardInterrupt:
    if not _requested:
        _requested.append(interrupt)
    return interrupt
