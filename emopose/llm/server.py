"""Which server answers at api_base: asked once, with a short timeout, before the probe request.

GET {api_base}/models (then /v1/models, Ollama's native base has no /v1) lists the served models and
says whose server it is: llama-cpp-python (`python -m llama_cpp.server`) lists them as owned_by "me",
llama.cpp's llama-server as "llamacpp", Ollama as "library", vLLM as "vllm"; any other answer is an
"openai-compatible" server. The question is also the liveness check: an endpoint that accepts TCP but
never answers fails within planner.client.probe_timeout_s, not after the call's timeout and retries.
A hosted provider (no api_base) is not asked: its kind is "hosted".
"""

from __future__ import annotations

import json
import urllib.error
import urllib.request
from dataclasses import dataclass, field

from emopose.llm.deadline import call_within
from emopose.llm.errors import LLMConfigError

OWNERS = {"me": "llama-cpp-python", "llamacpp": "llama-server", "library": "ollama", "vllm": "vllm"}
LISTING_BYTES = 1_000_000  # a models list is a few hundred bytes; never read a runaway body whole


@dataclass(frozen=True)
class Endpoint:
    """What check() found: the server, the structured-output form it took, the notes on forms it
    refused, and the probe's prompt size as the server counted it (its `usage`; None if not sent)."""

    kind: str  # llama-cpp-python | llama-server | ollama | vllm | openai-compatible | hosted | unchecked
    api_base: str | None = None
    models: tuple[str, ...] = ()  # as the server lists them (llama-cpp-python: the GGUF path or alias)
    structured_output: str | None = None
    notes: tuple[str, ...] = field(default=())
    probe_prompt_tokens: int | None = None

    def summary(self) -> dict:
        return {"server": self.kind, "api_base": self.api_base, "served_models": list(self.models),
                "structured_output": self.structured_output, "format_notes": list(self.notes),
                "probe_prompt_tokens": self.probe_prompt_tokens}


def _get_listing(url: str, api_key: str | None, timeout_s: float) -> dict | None:
    """The JSON a models route answers, None for an HTTP error (the server answered, it has no list)."""
    headers = {"Authorization": f"Bearer {api_key}"} if api_key else {}
    try:
        request = urllib.request.Request(url, headers=headers)
        with urllib.request.urlopen(request, timeout=timeout_s) as response:
            return json.loads(response.read(LISTING_BYTES))
    except urllib.error.HTTPError:
        return None
    except ValueError:  # not JSON: some other web server
        return None


def _kind(listing: dict | None) -> tuple[str | None, tuple[str, ...]]:
    rows = listing.get("data") if isinstance(listing, dict) else None
    if not isinstance(rows, list) or not rows:
        return None, ()
    rows = [r for r in rows if isinstance(r, dict)]
    owners = {OWNERS.get(str(r.get("owned_by"))) for r in rows} - {None}
    kind = owners.pop() if len(owners) == 1 else "openai-compatible"
    return kind, tuple(str(r.get("id")) for r in rows)


def identify(api_base: str | None, api_key: str | None, timeout_s: float) -> Endpoint:
    """The server at api_base; LLMConfigError when nothing answers or nothing answers in time."""
    if not api_base:
        return Endpoint("hosted")
    base = api_base.rstrip("/")
    base = base if "://" in base else f"http://{base}"
    urls = [f"{base}/models"] + ([] if base.endswith("/v1") else [f"{base}/v1/models"])
    for url in urls:
        try:
            listing = call_within(lambda u=url: _get_listing(u, api_key, timeout_s), timeout_s)
        except OSError as exc:  # refused, reset, unknown host, timed out (URLError is an OSError)
            reason = getattr(exc, "reason", exc)
            if isinstance(reason, TimeoutError):  # our deadline, or the socket's own (the same length)
                raise LLMConfigError(f"{api_base} accepts connections but sent no answer within "
                                     f"planner.client.probe_timeout_s = {timeout_s:g} s: is the server hung "
                                     "or still loading? Restart it or fix planner.client.api_base") from exc
            reason = getattr(reason, "strerror", None) or reason
            raise LLMConfigError(f"nothing answers at {api_base} ({reason}): start the server or fix "
                                 "planner.client.api_base") from exc
        kind, models = _kind(listing)
        if kind:
            return Endpoint(kind, api_base, models)
    return Endpoint("openai-compatible", api_base)
