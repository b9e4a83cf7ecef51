"""What the LLM planners share: prompt files, the client, concurrency, keyword fallback and counters.

A subclass says only what differs: the system prompt (`system_prompt`), the structured-output request
(`response_format`) and how the model's answer becomes contract JSON (`to_contract`). A call that
fails for good becomes a keyword-baseline answer with `fallback=True` and the error, so a benchmark
never crashes on one item; the parse stage then reports it as source "call_failed", never "model".
But `abort_after` consecutive failures that no retry can mend (refused connection, rejected key,
unknown model, context overflow) raise PlannerFailure: a run stops and names the cause instead
of scoring the keyword rules as the model. `check()` finds the same causes before the first item.

The model, endpoint, sampling, cache and run limits are one LLMClient, built from the planner's
`client:` node (conf/llm/hosted.yaml, conf/llm/local_server.yaml): a planner option names which.

Repeated passes: with the cache on, a second pass over the same items must not replay the first.
While `sampled` (temperature > 0) the cache key holds the draw: the client's `pass_index` (a job may
set it before pass k, or `planner.client.pass_index=K` on the command line) plus how many times
this client has already been asked the identical request. Either way five passes are five samples,
and rerunning a benchmark in a new process replays them from the cache. At temperature 0 the draw is
ignored and every pass shares one cached answer.
"""

from __future__ import annotations

import asyncio
import json
import logging
import time
from abc import ABC, abstractmethod
from collections.abc import Callable, Coroutine, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any

from emopose.llm.check import check_client
from emopose.llm.client import Completion, LLMClient
from emopose.llm.counters import CallCounters
from emopose.llm.server import Endpoint
from emopose.planners.base import BatchPlanner, CheckedPlanner, PlannerFailure, PlannerOutput, PlanRequest
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


class ChatPlanner(CheckedPlanner, BatchPlanner, ABC):
    """Base class. client: the model, endpoint and run limits (the `client:` node). max_demonstrations:
    use the first N demonstrations only (None: all)."""

    name = "chat"
    narrates = True  # the utterance is the robot's own line (see PlannerOutput.line)
    reports_progress = True  # plan_many(requests, on_done) calls on_done() as each answer comes

    def __init__(self, client: LLMClient, template: str, demonstrations: str,
                 max_demonstrations: int | None = None) -> None:
        if max_demonstrations is not None and max_demonstrations < 1:  # None: all demonstrations
            raise ValueError(f"planner.max_demonstrations = {max_demonstrations} must be >= 1")
        self.client = client
        self.template = PromptTemplate.load(template)
        self.demonstrations: list[Demonstration] = load_demonstrations(demonstrations)[:max_demonstrations]
        self.endpoint: Endpoint | None = None  # what check() found: server, structured output, prompt size

    # -- what subclasses define ------------------------------------------------------------------
    @abstractmethod
    def system_prompt(self) -> str:
        """The rendered system message for the current library."""

    def response_format(self) -> dict | None:
        """litellm's response_format for this planner's answers; None: the prompt alone asks for it."""
        return None

    def to_contract(self, text: str, request: PlanRequest) -> str:
        return text

    def format_offers(self, server: Endpoint) -> list[tuple[str, dict | None]]:
        """The structured-output forms check() may probe on `server`, best first: (name, response_format)."""
        return [("none", None)]

    # -- shared behaviour ------------------------------------------------------------------------
    @property
    def sampled(self) -> bool:
        return self.client.sampled

    def check(self) -> None:
        """Raise LLMConfigError when the model cannot work (see emopose/llm/check.py); keep what it found."""
        self.endpoint = check_client(self.client, self.messages(PlanRequest(PROBE_LINE)), self.format_offers)

    def stats(self) -> dict:
        """The model and the server it ran on (kind, served models, structured output, notes), calls,
        cache_hits, retries, failed_calls, model-call latency and queueing mean / p95 (s), prompt tokens."""
        endpoint = (self.endpoint or Endpoint("unchecked", self.client.api_base)).summary()
        return {"planner": self.name, "model": self.client.model, **endpoint, **self.client.counters.stats()}

    def reset_stats(self) -> None:
        """Start the counters afresh (e.g. after a warm-up call, or between a job's conditions)."""
        self.client.counters = CallCounters()

    def messages(self, request: PlanRequest) -> list[dict]:
        return chat_messages(self.system_prompt(), request)

    def plan(self, request: PlanRequest) -> PlannerOutput:
        pass_index, started = self.client.pass_index, time.perf_counter()
        try:
            completion = self.client.complete(self.messages(request), pass_index, self.response_format())
            raw = self.to_contract(completion.text, request)
        except Exception as exc:  # noqa: BLE001 - any failure after the retries: keyword answer, flagged
            return self._fallback(request, exc, pass_index, time.perf_counter() - started)
        return self._output(request, raw, time.perf_counter() - started, completion, pass_index)

    async def aplan(self, request: PlanRequest, gate: asyncio.Semaphore | None = None) -> PlannerOutput:
        """As plan(); latency_s is the model time, not the wait for a concurrency slot."""
        pass_index = self.client.pass_index
        try:
            completion = await self.client.acomplete(self.messages(request), pass_index, gate,
                                                     self.response_format())
            raw = self.to_contract(completion.text, request)
        except Exception as exc:  # noqa: BLE001 - as in plan()
            return self._fallback(request, exc, pass_index, getattr(exc, "latency_s", 0.0))
        return self._output(request, raw, completion.latency_s, completion, pass_index)

    def plan_many(self, requests: Sequence[PlanRequest],
                  on_done: Callable[[], None] | None = None) -> list[PlannerOutput]:
        """All requests concurrently (at most client.concurrency on the wire), answers in request order;
        on_done() after each answer (a progress line)."""

        async def one(request: PlanRequest, gate: asyncio.Semaphore) -> PlannerOutput:
            output = await self.aplan(request, gate)
            if on_done is not None:
                on_done()
            return output

        async def run() -> list[PlannerOutput]:
            gate = asyncio.Semaphore(self.client.concurrency)
            return list(await asyncio.gather(*(one(r, gate) for r in requests)))

        return run_coroutine(run()) if requests else []

    def _line(self, request: PlanRequest) -> str | None:
        return request.utterance if self.narrates else None

    def _fallback(self, request: PlanRequest, exc: Exception, pass_index: int,
                  latency_s: float) -> PlannerOutput:
        """The keyword rules' answer, flagged; too many unmendable failures in a row stop the run."""
        reason = self.client.failed_for_good(exc)
        if reason is not None:
            raise PlannerFailure(f"planner {self.name} ({self.client.model}) stopped after "
                                 f"{self.client.abort_after} failed calls in a row: {reason}") from exc
        error = f"{type(exc).__name__}: {exc}"[:500]
        log.warning("%s planner fell back to keyword rules: %s", self.name, error)
        records = keyword_records(request.utterance)
        raw = json.dumps({"reply": request.utterance, "gestures": [r.as_json() for r in records]})
        meta = {"model": self.client.model, "pass_index": pass_index}
        return PlannerOutput(raw=raw, latency_s=latency_s, fallback=True, error=error,
                             line=self._line(request), meta=meta)

    def _output(self, request: PlanRequest, raw: str, latency_s: float, completion: Completion,
                pass_index: int) -> PlannerOutput:
        self.client.answered()
        meta = {"model": self.client.model, "pass_index": pass_index, "attempts": completion.attempts,
                "cached": completion.cached, "finish_reason": completion.finish_reason,
                "queue_s": completion.queued_s}
        return PlannerOutput(raw=raw, latency_s=latency_s, meta=meta, line=self._line(request))
