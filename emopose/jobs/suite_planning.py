"""Planning a whole suite for the benchmark jobs: passes, chunks, progress, per-item failure isolation.

Requests go through emopose.planners.base.plan_all in chunks (so planners with a concurrent or batched
`plan_many` keep their speed, and a progress line can advance). If a chunk raises, its items are
retried one by one, and an item whose planner call raises is recorded as a failure (plan None) while
the run continues. Every answer is parsed with the one contract parser, parse_plan.
"""

from __future__ import annotations

import logging
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from emopose.contract import Plan
from emopose.planners.base import Planner, PlannerOutput, PlanRequest, plan_all
from emopose.stages.parse import parse_plan

log = logging.getLogger(__name__)

SAMPLED_PASSES = 5


@dataclass(frozen=True)
class PlannedItem:
    """One request's outcome: the parsed plan (None if the planner raised), latency, fallback flag."""

    plan: Plan | None
    latency_s: float | None = None
    fallback: bool = False
    error: str | None = None

    @property
    def top_class(self) -> str | None:
        return None if self.plan is None else self.plan.top_class

    @property
    def classes(self) -> tuple[str, ...] | None:
        return None if self.plan is None else tuple(r.cls for r in self.plan.records)


def resolve_passes(passes: int | None, planner: Planner) -> int:
    """`passes` as configured, or by default 5 for a sampled planner (planner.sampled) and 1 otherwise."""
    if passes is None:
        return SAMPLED_PASSES if getattr(planner, "sampled", False) else 1
    if int(passes) < 1:
        raise ValueError(f"passes must be >= 1, got {passes}")
    return int(passes)


def _outcome(output: PlannerOutput, request: PlanRequest) -> PlannedItem:
    plan = parse_plan(output.raw, request.utterance)
    fallback = bool(output.fallback) or plan.source == "keyword_fallback"
    return PlannedItem(plan, output.latency_s, fallback, output.error)


def _plan_chunk(planner: Planner, chunk: Sequence[PlanRequest]) -> list[PlannedItem]:
    try:
        outputs = plan_all(planner, chunk)
        if len(outputs) != len(chunk):
            raise RuntimeError(f"planner returned {len(outputs)} outputs for {len(chunk)} requests")
        return [_outcome(o, r) for o, r in zip(outputs, chunk)]
    except Exception:  # any planner error: isolate the failing item(s) one by one below
        log.warning("planner failed on a chunk of %d; retrying item by item", len(chunk), exc_info=True)
    items = []
    for request in chunk:
        try:
            items.append(_outcome(planner.plan(request), request))
        except Exception as exc:  # noqa: BLE001 - a failed item is a result, not a crash
            log.warning("planner failed on %r: %s", request.utterance[:60], exc)
            items.append(PlannedItem(plan=None, error=f"{type(exc).__name__}: {exc}"[:300]))
    return items


def plan_suite(planner: Planner, requests: Sequence[PlanRequest], label: str = "planning",
               chunk_size: int = 64, progress: bool = True) -> list[PlannedItem]:
    """Plan every request (in order), showing a progress line on stderr when `progress` is set."""
    from tqdm import tqdm

    results: list[PlannedItem] = []
    with tqdm(total=len(requests), desc=label, file=sys.stderr, disable=not progress,
              mininterval=0.5, unit="item", dynamic_ncols=True) as bar:
        for start in range(0, len(requests), chunk_size):
            chunk = requests[start:start + chunk_size]
            results.extend(_plan_chunk(planner, chunk))
            bar.update(len(chunk))
    return results


def latency_summary(items: Sequence[PlannedItem]) -> dict:
    """Planner latency in seconds: mean and 95th percentile over items that have one."""
    values = np.array([i.latency_s for i in items if i.latency_s is not None], dtype=float)
    if values.size == 0:
        return {"mean": None, "p95": None}
    return {"mean": float(values.mean()), "p95": float(np.percentile(values, 95))}


def run_summary(planned: Sequence[PlannedItem], started: float) -> dict:
    """The fields every suite job reports about its planning run (fallbacks, failures, latency, wall time)."""
    return {"fallbacks": sum(i.fallback for i in planned), "failures": sum(i.plan is None for i in planned),
            "latency_s": latency_summary(planned), "wall_s": time.perf_counter() - started}
