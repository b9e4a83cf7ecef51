"""Work that must not share the control loop's interpreter: a Python child process served over pipes.

Rendering (MuJoCo, JPEG) and espeak hold the GIL for milliseconds at a time; in the process that runs
the 50 Hz loop they delay its ticks however high the loop thread's priority is. A ChildProcess runs
`module.function(*args)` in a fresh interpreter (this checkout on its path, installed or not) and
exchanges pickled messages with it: the parent writes requests to the child's stdin, the child writes
answers through `answer_channel()`, and an answer that is an exception is raised in the parent.
"""

from __future__ import annotations

import contextlib
import os
import pickle
import select
import subprocess
import sys
from pathlib import Path
from typing import IO, Any


class ChildProcessGone(RuntimeError):
    """The child exited, or did not answer in time (it is then killed: its state is unknown)."""


class ChildProcess:
    def __init__(self, module: str, function: str, *args: Any, name: str = "child") -> None:
        self.name = name
        # a real-time parent's scheduling is inherited: the child's work must not compete with the loop
        command = (f"from emopose.execution.priority import normal_scheduling; normal_scheduling(); "
                   f"from {module} import {function}; {function}(*{args!r})")
        root = str(Path(__file__).resolve().parents[1])
        paths = filter(None, (root, os.environ.get("PYTHONPATH")))
        env = {**os.environ, "PYTHONPATH": os.pathsep.join(paths)}
        self.process = subprocess.Popen([sys.executable, "-c", command], stdin=subprocess.PIPE,
                                        stdout=subprocess.PIPE, env=env)

    @property
    def alive(self) -> bool:
        return self.process.poll() is None

    def request(self, message: Any, timeout_s: float | None = None) -> Any:
        """Send one request and return its answer (one request at a time: callers serialise)."""
        try:
            pickle.dump(message, self.process.stdin)
            self.process.stdin.flush()
        except OSError as exc:
            raise ChildProcessGone(f"the {self.name} process exited ({self.process.poll()})") from exc
        return self.receive(timeout_s)

    def receive(self, timeout_s: float | None = None) -> Any:
        # Answers are whole pickles written at once and only one is ever outstanding, so the buffered
        # reader holds nothing unread when select() looks at the pipe.
        if timeout_s is not None and not select.select([self.process.stdout], [], [], timeout_s)[0]:
            self.process.kill()
            raise ChildProcessGone(f"the {self.name} process did not answer within {timeout_s:g} s")
        try:
            answer = pickle.load(self.process.stdout)
        except EOFError as exc:
            raise ChildProcessGone(f"the {self.name} process exited ({self.process.wait()})") from exc
        if isinstance(answer, BaseException):
            raise answer
        return answer

    def close(self, timeout_s: float = 5.0) -> None:
        """Closing stdin ends the child's request loop; a child that lingers is killed."""
        with contextlib.suppress(OSError):  # the child may be gone already
            self.process.stdin.close()
        try:
            self.process.wait(timeout_s)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


def answer_channel() -> tuple[IO[bytes], IO[bytes]]:
    """In the child: (requests, answers). Anything a library prints to stdout goes to stderr instead,
    so it cannot corrupt the answer stream."""
    answers = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)
    return sys.stdin.buffer, answers


def send_answer(answers: IO[bytes], value: Any) -> None:
    """Write one answer; an exception that cannot be pickled travels as a RuntimeError with its text."""
    try:
        payload = pickle.dumps(value)
    except Exception:  # noqa: BLE001 -- e.g. an extension's exception type
        payload = pickle.dumps(RuntimeError(f"{type(value).__name__}: {value}"))
    answers.write(payload)
    answers.flush()


def serve_requests(build) -> None:
    """In the child: build the request handler (its outcome, None or the exception, is the first
    answer), then answer every request with handler(request) or the exception it raised, until the
    parent closes the pipe."""
    requests, answers = answer_channel()
    try:
        handle = build()
    except Exception as exc:  # noqa: BLE001 -- handed to the parent, which raises it
        return send_answer(answers, exc)
    send_answer(answers, None)
    while True:
        try:
            request = pickle.load(requests)
        except EOFError:
            return
        try:
            answer = handle(request)
        except Exception as exc:  # noqa: BLE001 -- handed to the parent, which raises it
            answer = exc
        send_answer(answers, answer)
