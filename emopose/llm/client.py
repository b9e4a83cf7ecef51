"""One chat-completion client for every LLM planner: litellm, our own retry loop, a response cache.

The retry loop is ours (litellm's and the OpenAI SDK's own retries are switched off) so the number
of attempts is visible to counters and tests, and so only transient failures are retried
(emopose/llm/errors.py sorts them). litellm is imported on first use: it takes seconds to
import and most runs never call it.
"""

from __future__ import annotations

import asyncio
import contextlib
import itertools
import threading
import time
from dataclasses import dataclass

from emopose.llm.cache import ResponseCache, cache_key
from emopose.llm.counters import CallCounters
from emopose.llm.deadline import await_within, call_within, clean_text
from emopose.llm.errors import LLMCallError, LLMConfigError, backoff_delay, cause, is_transient
from emopose.llm.errors import litellm_module as _litellm

NO_KEY_PLACEHOLDER = "no-key-needed"  # the OpenAI SDK refuses a missing key even for a local server


def effective_api_key(litellm, model: str, api_base: str | None, api_key: str | None) -> str | None:
    """For every litellm call (chat, ASR, TTS): the configured key; else None (litellm reads the provider's
    env var); a keyless local server (api_base set, no key anywhere) gets a placeholder: the OpenAI SDK
    refuses to send without one."""
    if api_key or not api_base:
        return api_key
    keys_in_environment = litellm.validate_environment(model=model).get("keys_in_environment")
    return None if keys_in_environment else NO_KEY_PLACEHOLDER


def usage_prompt_tokens(response) -> int | None:
    """The prompt's size as the server counted it (the response's `usage`), None when it sent none."""
    tokens = getattr(getattr(response, "usage", None), "prompt_tokens", None)
    return int(tokens) if isinstance(tokens, int) else None


@dataclass(frozen=True)
class Completion:
    text: str
    attempts: int
    cached: bool
    finish_reason: str | None = None
    latency_s: float = 0.0  # model time incl. retries and backoff; 0 for a cache hit
    queued_s: float = 0.0  # time spent waiting for a concurrency slot (plan_many), apart from latency_s


class LLMClient:
    """Chat completion with any litellm model string (openai/..., anthropic/..., ollama/..., hosted_vllm/...).

    Built from the planner's `client:` node (conf/llm/). Besides the call itself it holds what a run needs
    to know about the endpoint: `concurrency` (requests on the wire at once in a batch), `context_window`
    (tokens; None: litellm's model info), `probe` (check() sends one real request), `probe_timeout_s`
    (the most check() waits for the server to list its models), `abort_after` (unmendable failures in a
    row that stop a run) and `pass_index` (the draw while sampling). `timeout_s` is a hard deadline on
    each attempt, body included (emopose/llm/deadline.py)."""

    def __init__(self, model: str = "openai/gpt-4o-mini", api_base: str | None = None,
                 api_key: str | None = None, temperature: float = 0.7, max_tokens: int | None = 1024,
                 timeout_s: float = 60.0, max_retries: int = 3, backoff_s: float = 1.0,
                 backoff_max_s: float = 30.0, concurrency: int = 16, cache: bool = True,
                 cache_dir: str = "~/.cache/emopose/llm", pass_index: int = 0,
                 extra_params: dict | None = None, context_window: int | None = None, probe: bool = True,
                 abort_after: int = 5, probe_timeout_s: float = 5.0) -> None:
        if not isinstance(model, str) or not model.strip():
            raise LLMConfigError("planner.client.model is empty; give a litellm model string such as "
                                 "openai/gpt-4o-mini")
        for key, value, low in (("temperature", temperature, 0), ("timeout_s", timeout_s, 1e-3),
                                ("probe_timeout_s", probe_timeout_s, 1e-3),
                                ("max_retries", max_retries, 0), ("backoff_s", backoff_s, 0),
                                ("concurrency", concurrency, 1), ("abort_after", abort_after, 1),
                                ("context_window", context_window, 1)):
            if value is not None and value < low:  # None: litellm's context window
                raise LLMConfigError(f"planner.client.{key} = {value} must be >= {low}")
        self.model, self.api_base, self.api_key = model, api_base or None, api_key or None
        self.temperature, self.max_tokens, self.timeout_s = float(temperature), max_tokens, float(timeout_s)
        self.max_retries, self.backoff_s = int(max_retries), float(backoff_s)
        self.backoff_max_s, self.extra_params = float(backoff_max_s), dict(extra_params or {})
        self.concurrency, self.abort_after = int(concurrency), int(abort_after)
        self.pass_index = int(pass_index)  # a suite job may set it before each pass
        self.context_window, self.probe = context_window, bool(probe)
        self.probe_timeout_s = float(probe_timeout_s)
        self.cache = ResponseCache(cache_dir) if cache else None
        self.counters = CallCounters()
        self._key_resolved: tuple[str | None] | None = None  # decided on the first call (needs litellm)
        self._repeats: dict[str, int] = {}
        self._repeats_lock = threading.Lock()
        self._unmendable, self._unmendable_lock = 0, threading.Lock()

    @property
    def sampled(self) -> bool:
        """Repeated passes are independent draws (temperature > 0: the pass index keys the cache)."""
        return self.temperature > 0

    # -- a run's failures in a row ----------------------------------------------------------------
    def answered(self) -> None:
        """A request got its answer: the run of unmendable failures is broken."""
        with self._unmendable_lock:
            self._unmendable = 0

    def failed_for_good(self, exc: Exception) -> str | None:
        """Count a request that failed for good; the cause once `abort_after` failures that no retry can
        mend (refused, 401, 404, overflow) came in a row (the caller then stops its run), else None."""
        self.counters.add(failed_calls=1)
        reason = exc.cause if isinstance(exc, LLMCallError) else None
        with self._unmendable_lock:
            self._unmendable = self._unmendable + 1 if reason else 0
            return reason if self._unmendable >= self.abort_after else None

    # -- one request -------------------------------------------------------------------------
    def _key(self, messages: list[dict], pass_index: int, response_format: dict | None) -> str:
        return cache_key({"model": self.model, "api_base": self.api_base, "messages": messages,
                          "temperature": self.temperature, "max_tokens": self.max_tokens,
                          "extra": self.extra_params, "pass": pass_index if self.sampled else None,
                          **({"response_format": response_format} if response_format else {})})

    def call_kwargs(self, messages: list[dict], response_format: dict | None = None, **overrides) -> dict:
        """litellm.completion's arguments for one request (`overrides`: e.g. the probe's max_tokens=1)."""
        api_key = self._effective_key()
        kwargs = {"model": self.model, "messages": messages, "temperature": self.temperature,
                  "timeout": self.timeout_s, "max_retries": 0, "num_retries": 0, **self.extra_params}
        if self.max_tokens:
            kwargs["max_tokens"] = self.max_tokens
        if response_format:
            kwargs["response_format"] = response_format
        if self.api_base:
            kwargs["api_base"] = self.api_base
        if api_key:
            kwargs["api_key"] = api_key
        return {**kwargs, **overrides}

    def within_deadline(self, call):
        """call() (one blocking litellm request), or CallTimeout once timeout_s has passed."""
        return call_within(call, self.timeout_s)

    def _effective_key(self) -> str | None:
        if self._key_resolved is None:  # asked once: validate_environment reads the environment
            self._key_resolved = (effective_api_key(_litellm(), self.model, self.api_base, self.api_key),)
        return self._key_resolved[0]

    def _draw_key(self, messages: list[dict], pass_index: int, response_format: dict | None) -> str:
        """The cache key of this call. While sampling, the n-th identical request (n > 0) within this
        client's life is its own draw: five passes whose job never set pass_index still get five
        samples, and a rerun in a new process replays them in the same order."""
        key = self._key(messages, pass_index, response_format)
        if not self.sampled:
            return key
        with self._repeats_lock:
            repeat = self._repeats.get(key, 0)
            self._repeats[key] = repeat + 1
        return cache_key({"draw": key, "repeat": repeat}) if repeat else key

    def _lookup(self, messages: list[dict], pass_index: int | None,
                response_format: dict | None) -> tuple[str | None, Completion | None]:
        self.counters.add(calls=1)
        pass_index = self.pass_index if pass_index is None else pass_index
        if self.cache is None:
            return None, None
        key = self._draw_key(messages, pass_index, response_format)
        text = self.cache.get(key)
        if text is None:
            return key, None
        self.counters.add(cache_hits=1)
        return key, Completion(text, attempts=0, cached=True)

    def _retry_delay(self, exc: Exception, attempt: int, started: float, queued_s: float = 0.0) -> float:
        """Backoff before the next attempt, or raise LLMCallError when the failure is final."""
        if attempt >= self.max_retries or not is_transient(exc):
            latency = time.perf_counter() - started
            self.counters.latency(latency, queued_s)
            raise LLMCallError(f"{type(exc).__name__} after {attempt + 1} attempt(s): {str(exc)[:300]}",
                               latency, cause(exc, self.model, self.api_base)) from exc
        self.counters.add(retries=1)
        return backoff_delay(attempt, self.backoff_s, self.backoff_max_s, exc)

    def _finish(self, key: str | None, response, attempts: int, started: float,
                queued_s: float = 0.0) -> Completion:
        latency = time.perf_counter() - started
        self.counters.latency(latency, queued_s)
        choice = response.choices[0]
        text = clean_text(choice.message.content or "")
        self.counters.prompt(usage_prompt_tokens(response))
        if self.cache and key and text.strip():  # an empty answer is usually a provider hiccup: ask again
            self.cache.put(key, text, {"model": self.model, "finish_reason": choice.finish_reason})
        return Completion(text, attempts, cached=False, finish_reason=choice.finish_reason,
                          latency_s=latency, queued_s=queued_s)

    def complete(self, messages: list[dict], pass_index: int | None = None,
                 response_format: dict | None = None) -> Completion:  # type: ignore[return]
        """The answer to one chat request: from the cache, or from the model with retries (pass_index:
        the draw while sampling; None: this client's pass_index)."""
        key, hit = self._lookup(messages, pass_index, response_format)
        if hit is not None:
            return hit
        kwargs, started = self.call_kwargs(messages, response_format), time.perf_counter()
        for attempt in itertools.count():
            try:
                response = self.within_deadline(lambda: _litellm().completion(**kwargs))
            except Exception as exc:  # noqa: BLE001 - litellm raises many types; is_transient sorts them
                time.sleep(self._retry_delay(exc, attempt, started))
                continue
            return self._finish(key, response, attempt + 1, started)

    def open_stream(self, messages: list[dict]) -> tuple[object, int]:
        """litellm's stream of one chat request (stream=True) and the attempts it took: opened with the
        same retries as complete(), never cached (a streamed answer is spoken as it arrives)."""
        self.counters.add(calls=1)
        kwargs, started = self.call_kwargs(messages, stream=True), time.perf_counter()
        for attempt in itertools.count():
            try:
                return self.within_deadline(lambda: _litellm().completion(**kwargs)), attempt + 1
            except Exception as exc:  # noqa: BLE001 - as in complete()
                time.sleep(self._retry_delay(exc, attempt, started))

    async def acomplete(self, messages: list[dict], pass_index: int | None = None,
                        gate: asyncio.Semaphore | None = None,
                        response_format: dict | None = None) -> Completion:  # type: ignore[return]
        """As complete(); `gate` bounds requests on the wire (a call in backoff frees its slot). Waiting
        for a slot is the batch's queueing, not model latency: it is counted apart (queue_s)."""
        key, hit = self._lookup(messages, pass_index, response_format)
        if hit is not None:
            return hit
        kwargs, slot = self.call_kwargs(messages, response_format), gate or contextlib.nullcontext()
        started, queued_s = None, 0.0
        for attempt in itertools.count():
            queued = time.perf_counter()
            async with slot:
                waited = time.perf_counter() - queued
                queued_s += waited
                started = time.perf_counter() if started is None else started + waited
                try:
                    response = await await_within(_litellm().acompletion(**kwargs), self.timeout_s)
                except Exception as exc:  # noqa: BLE001 - as in complete()
                    delay = self._retry_delay(exc, attempt, started, queued_s)
                else:
                    return self._finish(key, response, attempt + 1, started, queued_s)
            await asyncio.sleep(delay)
