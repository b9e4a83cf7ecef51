"""What the LLM planners share: prompt files, the client, concurrency, keyword fallback and counters.

A subclass says only what differs: the system prompt (`system_prompt`), the structured-output request
(`response_format`) and how the model's answer becomes contract JSON (`to_contract`). A call that
fails for good becomes a keyword-baseline answer with `fallback=True` and the error, so a benchmark
never crashes on one item; the parse stage then reports it as source "call_failed", never "model".
But `abort_after` consecutive failures that no retry can mend (refused connection, rejected key,
unknown model, context overflow) raise PlannerFailure: a run stops and names the cause instead
of scoring the keyword rules as the model. `check()` finds the same causes before the first item.

Repeated passes: with the cache on, a second pass over the same items must not replay the first.
While `sampled` (temperature > 0) the cache key holds the draw: `pass_index` (a planner attribute the
bench job may set before pass k, or `planner.pass_index=K` on the command line) plus how many times
this planner has already been asked the identical request. Either way five passes are five samples,
and rerunning a benchmark in a new process replays them from the cache. At temperature 0 the draw is
ignored and every pass shares one cached answer.
"""

from __future__ import annotations

import asyncio
import json
import logging
import threading
import time
from abc import ABC, abstractmethod
from collections.abc import Coroutine, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any

from emopose.library import MotionLibrary
from emopose.llm.check import check_context, check_key, check_listening, check_route, probe
from emopose.llm.client import Completion, LLMClient
from emopose.llm.counters import CallCounters
from emopose.llm.errors import LLMCallError
from emopose.planners.base import PlannerFailure, PlannerOutput, PlanRequest
from emopose.planners.baselines.keyword import keyword_records
from emopose.planners.chat.prompting import (
    Demonstration,
    PromptTemplate,
    chat_messages,
    load_demonstrations,
)

log = logging.getLogger(__name__)

PROBE_LINE = "Hello, nice to meet you."  # the probe's user message: any short line will do


def run_coroutine(coro: Coroutine) -> Any:
    """Run a coroutine to completion from sync code, even when called inside a running event loop."""
    try:
        asyncio.get_running_loop()
    except RuntimeError:
        return asyncio.run(coro)
    with ThreadPoolExecutor(max_workers=1) as pool:  # e.g. called from an async web handler
        return pool.submit(asyncio.run, coro).result()


class ChatPlanner(ABC):
    """Base class; `**llm` are LLMClient's settings (model, api_base, temperature, cache, ...).

    max_demonstrations: use the first N demonstrations only (None: all). context_window: tokens, for
    local servers litellm has no card for (None: litellm's model info). probe: send one real request in
    check(). abort_after: consecutive unmendable call failures that stop a run."""

    name = "chat"
    narrates = True  # the utterance is the robot's own line (see PlannerOutput.line)

    def __init__(self, library: MotionLibrary, template: str, demonstrations: str, concurrency: int = 16,
                 pass_index: int = 0, max_demonstrations: int | None = None, context_window: int | None = None,
                 probe: bool = True, abort_after: int = 5, **llm: Any) -> None:
        for key, value in (("concurrency", concurrency), ("abort_after", abort_after),
                           ("max_demonstrations", max_demonstrations), ("context_window", context_window)):
            if value is not None and value < 1:  # None: all demonstrations / litellm's window
                raise ValueError(f"planner.{key} = {value} must be >= 1")
        self.library = library
        self.template = PromptTemplate.load(template)
        self.demonstrations: list[Demonstration] = load_demonstrations(demonstrations)[:max_demonstrations]
        self.concurrency, self.pass_index = int(concurrency), int(pass_index)
        self.context_window, self.probe, self.abort_after = context_window, bool(probe), int(abort_after)
        self.client = LLMClient(**llm)
        self._unmendable, self._unmendable_lock = 0, threading.Lock()

    # -- what subclasses define ------------------------------------------------------------------
    @abstractmethod
    def system_prompt(self) -> str:
        """The rendered system message for the current library."""

    def response_format(self) -> dict | None:
        """litellm's response_format for this planner's answers; None: the prompt alone asks for the format."""
        return None

    def to_contract(self, text: str, request: PlanRequest) -> str:
        return text

    # -- shared behaviour ------------------------------------------------------------------------
    @property
    def sampled(self) -> bool:
        return self.client.sampled

    def check(self) -> None:
        """Raise LLMConfigError when the model cannot work (see emopose/llm/check.py)."""
        if self.probe:
            check_listening(self.client.api_base)
        check_route(self.client)
        check_key(self.client)
        messages = self.messages(PlanRequest(PROBE_LINE))
        check_context(self.client, messages, self.context_window)
        if self.probe:
            probe(self.client, messages, self.response_format())

    def stats(self) -> dict:
        """calls, cache_hits, retries, failed_calls, and model-call latency and queueing mean / p95 (s)."""
        return {"planner": self.name, "model": self.client.model, **self.client.counters.stats()}

    def reset_stats(self) -> None:
        """Start the counters afresh (e.g. after a warm-up call, or between a job's conditions)."""
        self.client.counters = CallCounters()

    def messages(self, request: PlanRequest) -> list[dict]:
        return chat_messages(self.system_prompt(), request)

    def plan(self, request: PlanRequest) -> PlannerOutput:
        pass_index, started = self.pass_index, time.perf_counter()
        try:
            completion = self.client.complete(self.messages(request), pass_index, self.response_format())
            raw = self.to_contract(completion.text, request)
        except Exception as exc:  # noqa: BLE001 - any failure after the retries: keyword answer, flagged
            return self._fallback(request, exc, pass_index, time.perf_counter() - started)
        return self._output(request, raw, time.perf_counter() - started, completion, pass_index)

    async def aplan(self, request: PlanRequest, gate: asyncio.Semaphore | None = None) -> PlannerOutput:
        """As plan(); latency_s is the model time, not the wait for a concurrency slot."""
        pass_index = self.pass_index
        try:
            completion = await self.client.acomplete(self.messages(request), pass_index, gate,
                                                     self.response_format())
            raw = self.to_contract(completion.text, request)
        except Exception as exc:  # noqa: BLE001 - as in plan()
            return self._fallback(request, exc, pass_index, getattr(exc, "latency_s", 0.0))
        return self._output(request, raw, completion.latency_s, completion, pass_index)

    def plan_many(self, requests: Sequence[PlanRequest]) -> list[PlannerOutput]:
        """All requests concurrently (at most `concurrency` on the wire), answers in request order."""

        async def run() -> list[PlannerOutput]:
            gate = asyncio.Semaphore(self.concurrency)
            return list(await asyncio.gather(*(self.aplan(r, gate) for r in requests)))

        return run_coroutine(run()) if requests else []

    def _line(self, request: PlanRequest) -> str | None:
        return request.utterance if self.narrates else None

    def _count_failure(self, exc: Exception) -> None:
        """Count a call that failed for good; too many unmendable ones in a row stop the run."""
        reason = exc.cause if isinstance(exc, LLMCallError) else None
        with self._unmendable_lock:
            self._unmendable = self._unmendable + 1 if reason else 0
            stop = self._unmendable >= self.abort_after
        if stop:
            raise PlannerFailure(f"planner {self.name} ({self.client.model}) stopped after {self.abort_after} "
                                     f"failed calls in a row: {reason}") from exc

    def _fallback(self, request: PlanRequest, exc: Exception, pass_index: int, latency_s: float) -> PlannerOutput:
        self.client.counters.add(failed_calls=1)
        self._count_failure(exc)
        error = f"{type(exc).__name__}: {exc}"[:500]
        log.warning("%s planner fell back to keyword rules: %s", self.name, error)
        records = keyword_records(request.utterance)
        raw = json.dumps({"reply": request.utterance, "gestures": [r.as_json() for r in records]})
        return PlannerOutput(raw=raw, latency_s=latency_s, fallback=True, error=error, line=self._line(request),
                             meta={"model": self.client.model, "pass_index": pass_index})

    def _output(self, request: PlanRequest, raw: str, latency_s: float, completion: Completion,
                pass_index: int) -> PlannerOutput:
        with self._unmendable_lock:
            self._unmendable = 0
        meta = {"model": self.client.model, "pass_index": pass_index, "attempts": completion.attempts,
                "cached": completion.cached, "finish_reason": completion.finish_reason, "queue_s": completion.queued_s}
        return PlannerOutput(raw=raw, latency_s=latency_s, meta=meta, line=self._line(request))
