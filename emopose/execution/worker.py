"""Worker: a named daemon thread running one loop until asked to stop, the start/stop skeleton in one place.

The loop receives the stop flag (a threading.Event) and returns when it is set; it may also return on
its own (a fault). stop() may be called from the worker's own thread (a fault handler that tears its
owner down): it then only sets the flag, since a thread cannot join itself.
"""

from __future__ import annotations

import threading
from collections.abc import Callable


class Worker:
    def __init__(self, name: str, loop: Callable[[threading.Event], None], join_timeout_s: float) -> None:
        self.name, self._loop, self.join_timeout_s = name, loop, join_timeout_s
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def start(self) -> None:
        """Start the thread; a no-op until stop() when one was started already."""
        if self._thread is not None:
            return
        self._stop.clear()
        self._thread = threading.Thread(target=self._loop, args=(self._stop,), name=self.name, daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Ask the loop to return and wait for it (at most join_timeout_s); safe to call twice."""
        self._stop.set()
        thread, self._thread = self._thread, None
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout=self.join_timeout_s)

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()
