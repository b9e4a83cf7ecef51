"""StreamTap: a backend wrapper that keeps every command with the pose that followed it, tick by tick.

The suites that measure tracking (sim_suite, library_check, replay, sync_eval) put it between the
control loop and the backend (Session.tap) or send through it themselves; emopose/jobs/tracking.py
aligns and compares the streams it captures.
"""

from __future__ import annotations

import numpy as np

from emopose import CONTROL_DT
from emopose.backends.base import Backend
from emopose.backends.capabilities import SimulatedState
from emopose.recording import Recorder


class StreamTap(Backend):
    """Wraps a backend: forwards the Backend calls, and per send() keeps the command, the simulated pose
    after that tick's physics and any robot self-contacts (geom pairs) seen at that moment."""

    def __init__(self, backend: Backend) -> None:
        self.backend = backend
        self.realtime = backend.realtime
        self._simulated = backend if isinstance(backend, SimulatedState) else None
        self.times: list[float] = []
        self.commands: list[np.ndarray] = []
        self.states: list[np.ndarray] = []
        self.contacts: list[tuple[int, float, tuple[str, str]]] = []  # (tick, t, geom pair)

    @property
    def name(self) -> str:
        return self.backend.name

    @property
    def simulated(self) -> bool:
        """Whether `states` come from a simulator (else they repeat the commands)."""
        return self._simulated is not None

    def connect(self, recorder: Recorder | None) -> np.ndarray | None:
        return self.backend.connect(recorder)

    def measured(self) -> np.ndarray | None:
        return self.backend.measured()

    @property
    def is_connected(self) -> bool:
        return self.backend.is_connected

    def close(self) -> None:
        self.backend.close()

    def send(self, t: float, q: np.ndarray) -> np.ndarray:
        """Forward q and keep it (the requested command, as the suites compare it) with the pose after."""
        sent = self.backend.send(t, q)
        tick = len(self.times)
        self.times.append(t)
        self.commands.append(np.array(q, dtype=float))
        measured = self.backend.measured()
        self.states.append(np.array(q if measured is None else measured, dtype=float))
        sim = self._simulated
        if sim is not None and sim.data is not None and sim.data.ncon:  # naming the pairs costs ~0.2 ms
            self.contacts.extend((tick, t, pair) for pair in sim.contacts())
        return sent

    def __len__(self) -> int:
        return len(self.times)

    def window(self, first: int, last: int) -> tuple[np.ndarray, np.ndarray]:
        """Commands and states of ticks first..last inclusive, as (T, 14) arrays."""
        return np.array(self.commands[first:last + 1]), np.array(self.states[first:last + 1])

    def tick_at(self, t: float, start: int = 0) -> int:
        """Index of the tick stamped t (stream time), searching from `start`."""
        times = np.asarray(self.times[start:])
        k = int(np.argmin(np.abs(times - t)))
        if abs(times[k] - t) > CONTROL_DT / 2:
            raise LookupError(f"no tick at stream time {t:.3f} s")
        return start + k
