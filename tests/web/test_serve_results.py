"""serve's results count every turn (not the page's bounded log), by plan source with fallbacks apart, and
results.md tables them per turn; a failed planner call reaches the pages as a banner with its cause."""

from __future__ import annotations

from typing import get_args

from emopose.contract import PlanSource
from emopose.jobs.serve import served
from emopose.planners.base import PlannerOutput


def failing(planner):
    """The planner's call fails for good: the keyword answer, flagged as the fallback it is."""
    def plan(request):
        raw = planner.plan(request).raw
        return PlannerOutput(raw, fallback=True, error="APIConnectionError: Connection error")
    return plan


def test_results_count_every_turn_by_source_with_a_per_turn_table(serve_app):
    _, session = serve_app("serve.max_turns_kept=3")
    run = session.run
    for k in range(4):
        session._say(f"Welcome, visitor number {k}!", None)
    session._gesture("face_wave", 3, None)
    planner = run.runner.planner
    planner.plan = failing(type(planner)())
    session._say("The charging dock is over there.", None)
    assert len([m for m in session.log_since(0) if m["type"] == "turn"]) < 6  # the page's log is bounded
    results, markdown = served(run, session, run.session.loop.stats.summary())
    assert results["turns"] == 6 and results["kinds"] == {"say": 5, "gesture": 1}
    assert results["sources"] == {"model": 4, "scripted": 1, "call_failed": 1}
    assert results["fallbacks"] == 1 and results["planner_failures"] == 1
    assert results["history"]["messages_total"] == 10 and results["turns_file"] == "turns.jsonl"
    table = markdown.split("## Turns")[1].strip().splitlines()
    assert table[0].startswith("| turn | kind | plan source | fallback |") and len(table) == 2 + 6
    assert "| 6 | say | call_failed | yes |" in table[-1] and "{" not in markdown  # a table, not a dict


def test_a_failed_planner_call_reaches_the_pages_as_a_banner_until_a_call_succeeds(serve_app):
    _, session = serve_app()
    planner = session.run.runner.planner
    planner.plan = failing(type(planner)())
    turn = session._say("Where are the toilets?", None)
    banner = next(m for m in session.log_since(0) if m["type"] == "planner_failed")
    assert banner["turn_id"] == turn["turn_id"] and "Connection error" in banner["error"]
    assert banner["banner"].startswith("The planner could not be reached")
    assert session.status()["planner_failure"]["error"] == banner["error"]
    del planner.plan  # the planner answers again
    session._say("Thank you!", None)
    assert session.status()["planner_failure"] is None


def test_the_page_gets_words_for_every_plan_source():
    from emopose.web.serve_tally import SOURCE_WORDS

    assert set(SOURCE_WORDS) == set(get_args(PlanSource))
    assert all(" " in words and "_" not in words for words in SOURCE_WORDS.values())  # words, not names
