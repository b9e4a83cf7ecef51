"""What can go wrong on an LLM call, sorted: transient (retry), final (fall back), or fatal to the run.

A transient failure (429, 408/409, 5xx, a timeout, a dropped connection) is retried with backoff. A
failure that no retry can mend (a rejected key, an unknown model, a prompt larger than the context
window, nothing listening at api_base) is named in one line by `cause`, so the planner's check and
its abort say why a run cannot work instead of scoring keyword fallbacks as the model's answers.
"""

from __future__ import annotations

import contextlib
import logging
import random
import re
import socket

TRANSIENT_STATUS = frozenset({408, 409, 429})
_FORMAT_WORDS = re.compile(r"response_format|json_schema|json_object", re.IGNORECASE)


class LLMConfigError(ValueError):
    """The planner's model configuration cannot work; raised by check() before any item is planned."""


class LLMCallError(RuntimeError):
    """A call failed for good (after the retries, or at once for a non-transient error)."""

    def __init__(self, message: str, latency_s: float = 0.0, cause: str | None = None) -> None:
        super().__init__(message)
        self.latency_s = latency_s
        self.cause = cause  # set when no retry can mend it (see `cause` below)


def litellm_module():
    import litellm  # late: seconds to import, and most runs never call a hosted model
    litellm.suppress_debug_info = True  # otherwise every exception prints a help banner to stdout
    logging.getLogger("LiteLLM").setLevel(logging.WARNING)  # two INFO lines per call drown a run's log
    return litellm


def _chain(exc: BaseException):
    seen = set()
    while exc is not None and id(exc) not in seen:
        seen.add(id(exc))
        yield exc
        exc = exc.__cause__ or exc.__context__


def unreachable(exc: BaseException) -> bool:
    """Nothing answers at the address: refused, reset before an answer, or an unknown host."""
    return any(isinstance(e, (ConnectionError, socket.gaierror)) for e in _chain(exc))


def is_transient(exc: BaseException) -> bool:
    litellm = litellm_module()
    if isinstance(exc, (litellm.Timeout, litellm.APIConnectionError, TimeoutError)) or unreachable(exc):
        return True
    status = getattr(exc, "status_code", None)
    return isinstance(status, int) and (status in TRANSIENT_STATUS or status >= 500)


def refuses_format(exc: BaseException) -> bool:
    """The server rejected the request's response_format (llama-cpp-python answers HTTP 500 naming the
    field, OpenAI-style servers 400/422): the planner then tries the next form the server may take."""
    status = getattr(exc, "status_code", None)
    return status in (400, 422, 500) and bool(_FORMAT_WORDS.search(str(exc)))


def cause(exc: BaseException, model: str, api_base: str | None) -> str | None:
    """One line naming a failure that retrying cannot mend, with the setting to change; None otherwise."""
    litellm = litellm_module()
    where = api_base or "the provider's endpoint"
    detail = str(exc).splitlines()[0][-200:] if str(exc) else type(exc).__name__
    if isinstance(exc, litellm.ContextWindowExceededError):
        return (f"the prompt does not fit {model}'s context window ({detail}); use prompt=compact, lower "
                "planner.client.max_tokens, or start the server with a larger context")
    if unreachable(exc):
        return (f"nothing answers at {where} (connection refused or unknown host): start the server or fix "
                "planner.client.api_base")
    status = getattr(exc, "status_code", None)
    if status in (401, 403):
        return (f"{where} rejected the API key (HTTP {status}): set planner.client.api_key or the provider's "
                "env var")
    if status == 404:
        return (f"{where} does not know model {model!r} or the path (HTTP 404): check planner.client.model "
                "and planner.client.api_base")
    if isinstance(status, int) and 400 <= status < 500 and status not in TRANSIENT_STATUS:
        return f"{where} refused the request (HTTP {status}: {detail})"
    return None


def backoff_delay(attempt: int, base_s: float, cap_s: float, exc: BaseException | None = None) -> float:
    """Exponential backoff with jitter (so parallel calls do not retry in lockstep); honours Retry-After."""
    delay = min(cap_s, base_s * 2**attempt) * (0.5 + random.random() / 2)
    headers = getattr(exc, "litellm_response_headers", None) or {}
    with contextlib.suppress(TypeError, ValueError):
        delay = max(delay, min(cap_s, float(headers.get("retry-after", 0))))
    return delay
