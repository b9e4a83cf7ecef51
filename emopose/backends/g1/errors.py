"""Exceptions of the G1 backend and loco client (no heavy imports, safe to import anywhere)."""


class G1BackendError(RuntimeError):
    """The backend cannot (or can no longer) command the arms; the message says why."""


class G1ConnectionError(G1BackendError):
    """No usable robot state: nothing was commanded, or the arms were handed back."""


class LocoError(RuntimeError):
    """The loco service answered a request with a non-zero status code."""

    def __init__(self, api_id: int, code: int, message: str) -> None:
        super().__init__(message)
        self.api_id = api_id
        self.code = code


class LocoTimeoutError(TimeoutError):
    """No answer from the loco service in time."""
