"""Before any item is planned: can this LLM planner work at all? Each check fails with one line that
names the cause and the setting to change (LLMConfigError; the CLI exits 2 with it). In order:

1. the server at api_base answers a models listing within planner.client.probe_timeout_s (before
   litellm's seconds-long import, so a dead or hung local server is named in seconds), which also says
   whose server it is (emopose/llm/server.py);
2. the model string routes (litellm knows the provider);
3. a hosted provider has its API key;
4. the rendered prompt plus max_tokens fits the context window (planner.client.context_window, else
   litellm's model info; unknown windows are left to the probe);
5. the probe: one real request with the real system prompt and max_tokens=1, so a rejected key, an
   unknown model or a server-side context overflow is found in seconds, before any item could
   silently fall back to the keyword rules. It offers the structured-output forms the planner asks
   for, best first (emopose/llm/formats.py): a form the server refuses is noted in one line and the
   next is tried; the probe's `usage` gives the prompt's size as the server counts it.

planner.client.probe=false skips 1 and 5 (replaying a benchmark from the response cache with the
server off). The settings named are the planner's `client:` node (conf/llm/).
"""

from __future__ import annotations

import itertools
import logging
import time
from collections.abc import Callable

from emopose.llm.client import LLMClient, usage_prompt_tokens
from emopose.llm.errors import (
    LLMConfigError,
    backoff_delay,
    cause,
    is_transient,
    litellm_module,
    refuses_format,
)
from emopose.llm.server import Endpoint, identify

log = logging.getLogger(__name__)

FormatOffer = Callable[[Endpoint], list[tuple[str, dict | None]]]  # (form name, response_format), best first


class FormatRefused(LLMConfigError):
    """The server rejected the probe's response_format (the next form may do)."""


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


def probe(client: LLMClient, messages: list[dict], response_format: dict | None, retries: int = 1):
    """One real request (max_tokens=1, no cache, not counted) and its response; a transient error is
    retried `retries` times; FormatRefused when the server rejects `response_format`."""
    kwargs = client.call_kwargs(messages, response_format, max_tokens=1)
    for attempt in itertools.count():
        try:
            return client.within_deadline(lambda: litellm_module().completion(**kwargs))
        except Exception as exc:  # noqa: BLE001 - sorted below
            first = str(exc).splitlines()[0][:200] if str(exc) else type(exc).__name__
            if response_format and refuses_format(exc):
                raise FormatRefused(first) from exc
            reason = cause(exc, client.model, client.api_base)
            if reason is None and is_transient(exc) and attempt < retries:
                time.sleep(backoff_delay(attempt, client.backoff_s, client.backoff_max_s, exc))
                continue
            raise LLMConfigError(f"planner probe of {client.model} failed: "
                                 f"{reason or f'{type(exc).__name__}: {first}'}") from exc


def probe_formats(client: LLMClient, messages: list[dict], server: Endpoint, offers: FormatOffer) -> Endpoint:
    """Probe with each offered form until the server takes one; the server, that form and the notes."""
    offered, notes = offers(server), []
    for k, (form, response_format) in enumerate(offered):
        try:
            response = probe(client, messages, response_format)
        except FormatRefused as refused:
            following = offered[k + 1][0] if k + 1 < len(offered) else None
            notes.append(f"{server.kind} at {client.api_base or 'the provider'} refused structured output "
                         f"{form} ({str(refused)[:120]}); "
                         + (f"using {following}" if following else "nothing left to try"))
            log.warning("planner: %s", notes[-1])
            continue
        return Endpoint(server.kind, server.api_base, server.models, form, tuple(notes),
                        usage_prompt_tokens(response))
    tried = ", ".join(form for form, _ in offered)
    raise LLMConfigError(f"{server.kind} at {client.api_base or 'the provider'} refused every structured "
                         f"output tried ({tried}): set planner.structured_output=auto (tries what the server "
                         "takes) or planner.structured_output=none (the prompt alone asks for JSON)")


def check_client(client: LLMClient, messages: list[dict], offers: FormatOffer) -> Endpoint:
    """The checks above in order, for a request like `messages`; raise LLMConfigError naming the cause.
    Returns what was found: the server, the structured-output form it takes, the prompt's size."""
    server = identify(client.api_base, client.api_key, client.probe_timeout_s) if client.probe \
        else Endpoint("unchecked", client.api_base)
    if client.probe:
        log.info("planner: %s at %s%s; probing %s", server.kind, client.api_base or "the provider's endpoint",
                 f" serving {', '.join(server.models)}" if server.models else "", client.model)
    check_route(client)
    check_key(client)
    check_context(client, messages)
    if not client.probe:
        form = offers(server)[0][0]
        return Endpoint(server.kind, server.api_base, structured_output=form)
    found = probe_formats(client, messages, server, offers)
    log.info("planner: structured output %s; prompt %s tokens (the server's count)", found.structured_output,
             found.probe_prompt_tokens if found.probe_prompt_tokens is not None else "not reported")
    return found
