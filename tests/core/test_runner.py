from emopose.contract import GestureRecord, Plan


def test_a_turn_joins_the_dialogue_history_and_the_next_turn_sees_it(wired):
    first = wired.runner.run("Welcome to the lab!")
    second = wired.runner.run("Look over there.")
    assert first.request.history == ()
    assert [m["content"] for m in second.request.history] == ["Welcome to the lab!", first.plan.reply]
    assert len(wired.runner.history) == 4
    assert wired.runner.run("No.", use_history=False).request.history == ()


def test_a_scripted_plan_enters_at_resolve_without_a_planner_call(wired):
    class NoPlanner:
        name = "none"

        def plan(self, request):
            raise AssertionError("a scripted plan must not call the planner")

    wired.runner.planner = NoPlanner()
    plan = Plan.scripted("Over there.", GestureRecord(cls="pointing", variant="pointing_b", intensity=5))
    turn = wired.runner.run_plan(plan)
    assert turn.planner_output is None and turn.plan is plan
    assert turn.resolved[0].entry.name == "pointing_b" and turn.resolved[0].rule == "exact"
    assert "parse" not in turn.stage_s and turn.dispatched.completed
    assert wired.runner.history == []


def test_the_session_opens_once_whoever_asks(wired):
    loop = wired.session.open()
    wired.runner.run("Hi.")
    assert wired.session.open() is loop and wired.session.is_open
