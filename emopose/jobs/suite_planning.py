"""Planning a whole suite for the benchmark jobs: passes, chunks, progress, per-item failure isolation.

Requests go through emopose.planners.base.plan_all in chunks (so planners with a concurrent or batched
`plan_many` keep their speed). The progress line advances per completed answer for a planner that
reports them (`reports_progress`: the LLM planners, whose answers take seconds each, so the ETA shows
from the first answers), per chunk otherwise. If a chunk raises, its items are
retried one by one, and an item whose planner call raises is recorded as a failure (plan None) while
the run continues; a PlannerFailure (the planner cannot answer at all) stops the run instead. Every
answer is parsed with the one contract parser (parse_output), whose Plan.source is each prediction's
source; `fallbacks` counts every answer that is not a usable model record, and a run whose fallback
share exceeds `max_fallback_share` is written, marked, and then fails (suite_output).
"""

from __future__ import annotations

import logging
import sys
import time
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from emopose.contract import Plan
from emopose.planners.base import Planner, PlannerFailure, PlannerOutput, PlanRequest, plan_all
from emopose.results import JobFailure, JobOutput
from emopose.stages.parse import parse_output

log = logging.getLogger(__name__)

SAMPLED_PASSES = 5
MAX_FALLBACK_SHARE = 0.2  # the default limit of a suite job's job.max_fallback_share


@dataclass(frozen=True)
class PlannedItem:
    """One request's outcome: the parsed plan (None if the planner raised), latency, error."""

    plan: Plan | None
    latency_s: float | None = None
    error: str | None = None
    queue_s: float | None = None  # waiting for a concurrency slot, apart from latency_s (LLM planners)

    @property
    def source(self) -> str:
        """Where the prediction came from (PlanSource), or "failed" when the planner raised."""
        return "failed" if self.plan is None else self.plan.source

    @property
    def fallback(self) -> bool:
        return self.plan is not None and self.plan.fallback

    @property
    def top_class(self) -> str | None:
        return None if self.plan is None else self.plan.top_class

    @property
    def classes(self) -> tuple[str, ...] | None:
        return None if self.plan is None else tuple(r.cls for r in self.plan.records)


def check_passes(passes: int | None) -> None:
    """`passes` is null or >= 1; a suite job checks it when it is built, before anything starts."""
    if passes is not None and int(passes) < 1:
        raise ValueError(f"passes={passes}: must be >= 1 (null: {SAMPLED_PASSES} for a sampled planner, "
                         f"1 otherwise)")


def load_suite(loader: Callable[..., list], path: str, *args: object) -> list:
    """A suite job's items, read when the job is built: a missing or unreadable file, or one without
    items, is a ValueError naming bench.path (a config error, exit 2, before anything starts)."""
    try:
        items = loader(path, *args)
    except OSError as exc:  # missing, a folder, unreadable
        raise ValueError(f"bench.path={path}: {exc.strerror or exc}") from exc
    if not items:
        raise ValueError(f"bench.path={path}: no items")
    return items


def resolve_passes(passes: int | None, planner: Planner) -> int:
    """`passes` as configured, or by default 5 for a sampled planner (planner.sampled) and 1 otherwise."""
    check_passes(passes)
    return (SAMPLED_PASSES if planner.sampled else 1) if passes is None else int(passes)


def _outcome(output: PlannerOutput, request: PlanRequest) -> PlannedItem:
    return PlannedItem(parse_output(output, request.utterance), output.latency_s, output.error,
                       output.meta.get("queue_s"))


def _plan_chunk(planner: Planner, chunk: Sequence[PlanRequest],
                on_done: Callable[[], None]) -> list[PlannedItem]:
    try:
        outputs = (planner.plan_many(chunk, on_done=on_done) if getattr(planner, "reports_progress", False)
                   else plan_all(planner, chunk))
        if len(outputs) != len(chunk):
            raise RuntimeError(f"planner returned {len(outputs)} outputs for {len(chunk)} requests")
        return [_outcome(o, r) for o, r in zip(outputs, chunk)]
    except PlannerFailure:
        raise
    except Exception:  # any planner error: isolate the failing item(s) one by one below
        log.warning("planner failed on a chunk of %d; retrying item by item", len(chunk), exc_info=True)
    items = []
    for request in chunk:
        try:
            items.append(_outcome(planner.plan(request), request))
        except PlannerFailure:
            raise
        except Exception as exc:  # noqa: BLE001 - a failed item is a result, not a crash
            log.warning("planner failed on %r: %s", request.utterance[:60], exc)
            items.append(PlannedItem(plan=None, error=f"{type(exc).__name__}: {exc}"[:300]))
    return items


def planner_report(planner: Planner) -> dict:
    """For results.json: the planner's own account of its run where it keeps one (an LLM planner: model,
    server, structured output, calls, latency, prompt tokens as the server counted them)."""
    stats = getattr(planner, "stats", None)
    return {"planner_stats": stats()} if callable(stats) else {}


def plan_suite(planner: Planner, requests: Sequence[PlanRequest], label: str = "planning",
               chunk_size: int = 64, progress: bool = True) -> list[PlannedItem]:
    """Plan every request (in order), showing a progress line on stderr when `progress` is set."""
    from tqdm import tqdm

    results: list[PlannedItem] = []
    with tqdm(total=len(requests), desc=label, file=sys.stderr, disable=not progress,
              mininterval=0.5, unit="item", dynamic_ncols=True) as bar:
        for start in range(0, len(requests), chunk_size):
            chunk = requests[start:start + chunk_size]
            results.extend(_plan_chunk(planner, chunk, lambda: bar.update(1)))
            bar.update(len(results) - bar.n)  # the rest of the chunk (all of it for a chunk-wise planner)
    return results


def latency_summary(items: Sequence[PlannedItem], attribute: str = "latency_s") -> dict:
    """Planner latency (or queueing) in seconds: mean and 95th percentile over items that have one."""
    values = np.array([getattr(i, attribute) for i in items if getattr(i, attribute) is not None],
                      dtype=float)
    if values.size == 0:
        return {"mean": None, "p95": None}
    return {"mean": float(values.mean()), "p95": float(np.percentile(values, 95))}


def run_summary(planned: Sequence[PlannedItem], started: float,
                max_fallback_share: float = MAX_FALLBACK_SHARE) -> dict:
    """The fields every suite job reports about its planning run: fallbacks (and their share of all
    answers, against the limit), failures, the count of each source, latency and wall time."""
    if not 0.0 <= max_fallback_share <= 1.0:
        raise ValueError(f"job.max_fallback_share = {max_fallback_share} must be in [0, 1]")
    fallbacks = sum(i.fallback for i in planned)
    share = fallbacks / len(planned) if planned else 0.0
    return {"fallbacks": fallbacks, "fallback_share": share, "max_fallback_share": max_fallback_share,
            "fallback_exceeded": share > max_fallback_share, "failures": sum(i.plan is None for i in planned),
            "sources": dict(Counter(i.source for i in planned)), "latency_s": latency_summary(planned),
            "queue_s": latency_summary(planned, "queue_s"),
            "wall_s": time.perf_counter() - started}


def suite_output(results: dict, markdown: str) -> JobOutput:
    """What a suite job returns. A run that fell back too often is written and printed all the same,
    then fails (exit 2) rather than pass the keyword rules off as the planner's score."""
    if results["fallback_exceeded"]:
        raise JobFailure(results, markdown, PlannerFailure(
            f"planner {results['method']} fell back on {results['fallbacks']} answers "
            f"({100 * results['fallback_share']:.1f} % > job.max_fallback_share "
            f"{100 * results['max_fallback_share']:.0f} %; sources {results['sources']}); the results are "
            f"written and marked, but are not the planner's score"))
    return results, markdown
