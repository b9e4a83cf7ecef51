"""python -m tests.recording.witness OVERRIDES...: `python -m emopose OVERRIDES...` with a witness of every
recorded message, for the kill -9 tests.

Each message the Recorder takes is logged as one line `<wall ns> <log time ns> <topic>` to the file named
by $EMOPOSE_WITNESS, with an unbuffered write(2) straight after the Recorder's own call, and each flush
that reached the disk as `<wall ns it began> flush <wall ns its fsync returned>`: a SIGKILL leaves every
line the kernel took, so the test knows which messages existed before which flush (a virtual-clock job's
log times say nothing about the wall clock, and on a busy machine the flusher's wall cadence says little).
"""

from __future__ import annotations

import os
import sys
import time

from emopose.recording import Recorder

WITNESS = "EMOPOSE_WITNESS"


def witness_every_message(fd: int) -> None:
    record = Recorder._queue

    def witnessed(self, topic, offset_s, payload):
        was_closed = self._closed.is_set()  # a closed recorder drops the message
        record(self, topic, offset_s, payload)
        if not was_closed:
            stamp = self.start_ns + int(round(offset_s * 1e9))  # the log time Recorder._queue gave it
            os.write(fd, f"{time.time_ns()} {stamp} {topic}\n".encode())

    Recorder._queue = witnessed
    flush = Recorder.flush

    def witnessed_flush(self):
        began = time.time_ns()
        flush(self)
        os.write(fd, f"{began} flush {time.time_ns()}\n".encode())

    Recorder.flush = witnessed_flush


def read_witness(path) -> tuple[list[tuple[int, int, str]], list[tuple[int, int]]]:
    """(wall ns, log time ns, topic) of every witnessed message; (began, ended) wall ns of every flush
    that was on disk before the kill."""
    messages, flushes = [], []
    for line in path.read_text().splitlines():
        first, second, third = line.split(" ", 2)
        if second == "flush":
            flushes.append((int(first), int(third)))
        else:
            messages.append((int(first), int(second), third))
    return messages, flushes


if __name__ == "__main__":
    witness_every_message(os.open(os.environ[WITNESS], os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644))
    from emopose.__main__ import cli

    sys.argv = ["emopose", *sys.argv[1:]]
    cli()
