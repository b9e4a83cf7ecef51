"""The pages watching the robot: a cap on how many, and a push rate that degrades per page.

Every open page gets state, log messages and frames pushed over its WebSocket; each push costs the one
event loop that also answers the API. So: at most `serve.max_clients` pages at once (one more is
accepted and closed at once with code 1013, "try again later", and a reason saying so); the pushes of
all pages share a budget of `serve.push_budget_hz` cycles a second (a page's rate is its share, at most
the faster of serve.state_hz and serve.sim_fps; state goes out at most at state_hz); and a page whose
cycle comes back late (the loop is busy, or the page reads slowly) halves its own rate, down to
`serve.min_push_hz`, and regains it slowly once cycles are on time.
Frames follow the same rate (a page gets the newest frame each cycle, never a backlog).
"""

from __future__ import annotations

import threading

from emopose.web.settings import ServeSettings

REFUSED_CODE = 1013  # RFC 6455 "Try Again Later"
SLOWER, FASTER = 2.0, 0.8  # backoff factor per late cycle, and per on-time cycle while recovering
LATE_SHARE, ON_TIME_SHARE = 0.5, 0.1  # a cycle late by half its period backs off; within a tenth recovers


class Clients:
    """Admission and the shared push budget; counters for /api/status and results.json."""

    def __init__(self, settings: ServeSettings) -> None:
        self.settings = settings
        self.open = self.accepted = self.refused = self.slowed = 0
        self._lock = threading.Lock()

    def admit(self) -> bool:
        """Take one page if there is room (the caller closes a refused one with refusal())."""
        with self._lock:
            if self.open >= self.settings.max_clients:
                self.refused += 1
                return False
            self.open += 1
            self.accepted += 1
            return True

    def leave(self) -> None:
        with self._lock:
            self.open -= 1

    def count_slowed(self) -> None:
        with self._lock:
            self.slowed += 1

    def refusal(self) -> str:
        return (f"too many pages open: this server takes {self.settings.max_clients} at once "
                "(serve.max_clients); close one and reload")

    def share_hz(self) -> float:
        """One page's cycle rate: its share of the budget, within [min_push_hz, the fastest push]."""
        s = self.settings
        return min(max(s.state_hz, s.sim_fps), max(s.min_push_hz, s.push_budget_hz / max(1, self.open)))

    def counters(self) -> dict:
        return {"open": self.open, "accepted": self.accepted, "refused": self.refused,
                "slowed": self.slowed, "max_clients": self.settings.max_clients,
                "push_hz_each": round(self.share_hz(), 2)}


class Pacer:
    """One page's cycle period: its budget share, slowed while its cycles come back late."""

    def __init__(self, clients: Clients) -> None:
        self.clients = clients
        self.backoff = 1.0  # >= 1: how many times slower than the share this page runs now

    def next_period(self, late_s: float) -> float:
        """The period to wait before the next cycle, given how late the last one came back (seconds)."""
        share = self.clients.share_hz()
        period = self.backoff / share
        floor_hz = min(share, self.clients.settings.min_push_hz)
        if late_s > LATE_SHARE * period and self.backoff < share / floor_hz:
            self.backoff = min(self.backoff * SLOWER, share / floor_hz)
            self.clients.count_slowed()
        elif late_s < ON_TIME_SHARE * period:
            self.backoff = max(1.0, self.backoff * FASTER)
        return self.backoff / share
