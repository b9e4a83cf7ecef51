"""What the LLM planners share: prompt files, the client, concurrency, keyword fallback and counters.

A subclass says only what differs: the system prompt (`system_prompt`) and how the model's answer
becomes contract JSON (`to_contract`). Every failure that survives the client's retries becomes a
keyword-baseline answer with `fallback=True` and the error, so a benchmark never crashes on one item.

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
import time
from abc import ABC, abstractmethod
from collections.abc import Coroutine, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any

from emopose.library import MotionLibrary
from emopose.planners.base import PlannerOutput, PlanRequest
from emopose.planners.keyword import keyword_records
from emopose.planners.llm_client import CallCounters, Completion, LLMClient
from emopose.planners.prompting import (
    Demonstration,
    PromptTemplate,
    chat_messages,
    load_demonstrations,
)

log = logging.getLogger(__name__)


def run_coroutine(coro: Coroutine) -> Any:
    """Run a coroutine to completion from sync code, even when called inside a running event loop."""
    try:
        asyncio.get_running_loop()
    except RuntimeError:
        return asyncio.run(coro)
    with ThreadPoolExecutor(max_workers=1) as pool:  # e.g. called from an async web handler
        return pool.submit(asyncio.run, coro).result()


class ChatPlanner(ABC):
    """Base class; `**llm` are LLMClient's settings (model, api_base, temperature, cache, ...)."""

    name = "chat"

    def __init__(self, library: MotionLibrary, template: str, demonstrations: str, concurrency: int = 16,
                 pass_index: int = 0, **llm: Any) -> None:
        if concurrency < 1:
            raise ValueError(f"planner.concurrency = {concurrency} must be >= 1")
        self.library = library
        self.template = PromptTemplate.load(template)
        self.demonstrations: list[Demonstration] = load_demonstrations(demonstrations)
        self.concurrency = int(concurrency)
        self.pass_index = int(pass_index)
        self.client = LLMClient(**llm)

    # -- what subclasses define ------------------------------------------------------------------
    @abstractmethod
    def system_prompt(self) -> str:
        """The rendered system message for the current library."""

    def to_contract(self, text: str, request: PlanRequest) -> str:
        return text

    # -- shared behaviour ------------------------------------------------------------------------
    @property
    def sampled(self) -> bool:
        return self.client.sampled

    def check(self) -> None:
        """Raise LLMConfigError for an unroutable model or a missing API key (jobs call this first)."""
        self.client.check()

    def stats(self) -> dict:
        """calls, cache_hits, retries, fallbacks, and model-call latency mean / p95 (s)."""
        return {"planner": self.name, "model": self.client.model, **self.client.counters.stats()}

    def reset_stats(self) -> None:
        """Start the counters afresh (e.g. after a warm-up call, or between a job's conditions)."""
        self.client.counters = CallCounters()

    def messages(self, request: PlanRequest) -> list[dict]:
        return chat_messages(self.system_prompt(), request)

    def plan(self, request: PlanRequest) -> PlannerOutput:
        pass_index, started = self.pass_index, time.perf_counter()
        try:
            completion = self.client.complete(self.messages(request), pass_index)
            raw = self.to_contract(completion.text, request)
        except Exception as exc:  # noqa: BLE001 - any failure after the retries: keyword answer, flagged
            return self._fallback(request, exc, pass_index, time.perf_counter() - started)
        return self._output(raw, time.perf_counter() - started, completion, pass_index)

    async def aplan(self, request: PlanRequest, gate: asyncio.Semaphore | None = None) -> PlannerOutput:
        """As plan(); latency_s is the model time, not the wait for a concurrency slot."""
        pass_index = self.pass_index
        try:
            completion = await self.client.acomplete(self.messages(request), pass_index, gate)
            raw = self.to_contract(completion.text, request)
        except Exception as exc:  # noqa: BLE001 - as in plan()
            return self._fallback(request, exc, pass_index, getattr(exc, "latency_s", 0.0))
        return self._output(raw, completion.latency_s, completion, pass_index)

    def plan_many(self, requests: Sequence[PlanRequest]) -> list[PlannerOutput]:
        """All requests concurrently (at most `concurrency` on the wire), answers in request order."""

        async def run() -> list[PlannerOutput]:
            gate = asyncio.Semaphore(self.concurrency)
            return list(await asyncio.gather(*(self.aplan(r, gate) for r in requests)))

        return run_coroutine(run()) if requests else []

    def _fallback(self, request: PlanRequest, exc: Exception, pass_index: int, latency_s: float) -> PlannerOutput:
        self.client.counters.add(fallbacks=1)
        error = f"{type(exc).__name__}: {exc}"[:500]
        log.warning("%s planner fell back to keyword rules: %s", self.name, error)
        records = keyword_records(request.utterance)
        raw = json.dumps({"reply": request.utterance, "gestures": [r.as_json() for r in records]})
        return PlannerOutput(raw=raw, latency_s=latency_s, fallback=True, error=error,
                             meta={"model": self.client.model, "pass_index": pass_index})

    def _output(self, raw: str, latency_s: float, completion: Completion, pass_index: int) -> PlannerOutput:
        meta = {"model": self.client.model, "pass_index": pass_index, "attempts": completion.attempts,
                "cached": completion.cached, "finish_reason": completion.finish_reason}
        return PlannerOutput(raw=raw, latency_s=latency_s, meta=meta)
