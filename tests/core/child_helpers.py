"""Request handlers the child-process tests run in a real child (as tests.core.child_helpers)."""

from __future__ import annotations

import time

from emopose.child_process import serve_requests


def serve_echo() -> None:
    serve_requests(lambda: _echo)


def serve_broken() -> None:
    serve_requests(_refuse_to_start)


def _echo(request):
    kind, value = request
    if kind == "print":  # a library writing to stdout must not corrupt the answers
        print("noise on stdout", value)
        return value
    if kind == "raise":
        raise ValueError(value)
    if kind == "sleep":
        time.sleep(value)
        return value
    if kind == "exit":
        raise SystemExit(3)
    return value


def _refuse_to_start():
    raise OSError("no EGL here")
