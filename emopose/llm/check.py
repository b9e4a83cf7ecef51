"""Before any item is planned: can this LLM planner work at all? Each check fails with one line that
names the cause and the setting to change (LLMConfigError; the CLI exits 2 with it). In order:

1. something accepts a TCP connection at api_base (before litellm's seconds-long import, so a dead
   local server is named at once);
2. the model string routes (litellm knows the provider);
3. a hosted provider has its API key;
4. the rendered prompt plus max_tokens fits the context window (planner.client.context_window, else
   litellm's model info; unknown windows are left to the probe);
5. the probe: one real request with the real system prompt and max_tokens=1, so a rejected key, an
   unknown model or a server-side context overflow is found in seconds, before any item could
   silently fall back to the keyword rules.

planner.client.probe=false skips 1 and 5 (replaying a benchmark from the response cache with the
server off). The settings named are the planner's `client:` node (conf/llm/).
"""

from __future__ import annotations

import socket
import time
from urllib.parse import urlsplit

from emopose.llm.client import LLMClient
from emopose.llm.errors import LLMConfigError, backoff_delay, cause, is_transient, litellm_module


def check_listening(api_base: str | None, timeout_s: float = 3.0) -> None:
    """Something accepts connections at api_base (a hosted provider's endpoint is left to the probe)."""
    if not api_base:
        return
    url = urlsplit(api_base if "://" in api_base else f"http://{api_base}")
    port = url.port or (443 if url.scheme == "https" else 80)
    try:
        socket.create_connection((url.hostname or "127.0.0.1", port), timeout=timeout_s).close()
    except OSError as exc:
        raise LLMConfigError(f"nothing answers at {api_base} ({exc.strerror or exc}): start the server or "
                             "fix planner.client.api_base") from exc


def check_route(client: LLMClient) -> None:
    try:
        litellm_module().get_llm_provider(model=client.model, api_base=client.api_base)
    except Exception as exc:
        raise LLMConfigError(
            f"planner.client.model = {client.model!r} is not a litellm model string "
            f"({str(exc).splitlines()[0][:160]}); use provider/name, e.g. openai/gpt-4o-mini, "
            "anthropic/claude-3-5-haiku-latest, or hosted_vllm/NAME with planner.client.api_base") from exc


def check_key(client: LLMClient) -> None:
    if client.api_base or client.api_key:
        return  # a local or proxy server: it decides whether it wants a key (the probe asks it)
    env = litellm_module().validate_environment(model=client.model)
    if not env.get("keys_in_environment"):
        raise LLMConfigError(
            f"planner.client.model = {client.model!r} needs {env.get('missing_keys')} in the environment: "
            "export it, set planner.client.api_key, or point planner.client.api_base at a local "
            "OpenAI-compatible server")


def context_window(model: str, configured: int | None) -> tuple[int | None, str]:
    """The model's context window in tokens and where the number comes from; (None, ...) when unknown."""
    if configured:
        return int(configured), "planner.client.context_window"
    try:
        info = litellm_module().get_model_info(model)
    except Exception:  # noqa: BLE001 - litellm raises on any model it has no card for
        return None, "unknown"
    window = info.get("max_input_tokens") or info.get("max_tokens")
    return (int(window), "litellm's model info") if window else (None, "unknown")


def prompt_tokens(model: str, messages: list[dict]) -> int:
    """litellm's token count of the messages (the model's tokenizer where litellm has it, else
    tiktoken)."""
    return int(litellm_module().token_counter(model=model, messages=messages))


def check_context(client: LLMClient, messages: list[dict]) -> None:
    window, source = context_window(client.model, client.context_window)
    if window is None:
        return
    tokens, answer = prompt_tokens(client.model, messages), client.max_tokens or 0
    if tokens + answer > window:
        raise LLMConfigError(
            f"the prompt ({tokens} tokens) plus planner.client.max_tokens ({answer}) exceeds "
            f"{client.model}'s context window of {window} tokens ({source}); use prompt=compact, lower "
            "planner.client.max_tokens, or raise the server's context (and planner.client.context_window)")


def probe(client: LLMClient, messages: list[dict], response_format: dict | None, retries: int = 1) -> None:
    """One real request (max_tokens=1, no cache, not counted); a transient error is retried `retries`
    times."""
    kwargs = client.call_kwargs(messages, response_format, max_tokens=1)
    for attempt in range(retries + 1):
        try:
            litellm_module().completion(**kwargs)
            return
        except Exception as exc:  # noqa: BLE001 - sorted below
            reason = cause(exc, client.model, client.api_base)
            if reason is None and is_transient(exc) and attempt < retries:
                time.sleep(backoff_delay(attempt, client.backoff_s, client.backoff_max_s, exc))
                continue
            first = str(exc).splitlines()[0][:200] if str(exc) else type(exc).__name__
            raise LLMConfigError(f"planner probe of {client.model} failed: "
                                 f"{reason or f'{type(exc).__name__}: {first}'}") from exc


def check_client(client: LLMClient, messages: list[dict], response_format: dict | None) -> None:
    """The checks above in order, for a request like `messages`; raise LLMConfigError naming the cause."""
    if client.probe:
        check_listening(client.api_base)
    check_route(client)
    check_key(client)
    check_context(client, messages)
    if client.probe:
        probe(client, messages, response_format)
