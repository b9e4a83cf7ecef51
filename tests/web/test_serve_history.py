"""A served session's dialogue stays bounded: planners read a window (turns and tokens), each message is
recorded once on /dialogue, and a /request record does not grow with the conversation."""

from __future__ import annotations

import json

from emopose.recording import read_recording
from emopose.turn.dialogue import CHANNEL, Dialogue, HistoryWindow, estimated_tokens


def test_the_window_keeps_the_newest_turns_within_both_bounds():
    dialogue = Dialogue(HistoryWindow(turns=4, tokens=10_000))
    for k in range(30):
        dialogue.exchange(f"question {k}", f"answer {k}")
    asked = [m["content"] for m in dialogue.request("next").history][::2]
    assert asked == [f"question {k}" for k in range(26, 30)]
    assert dialogue.total == 60 and dialogue.dropped_turns == 26

    by_tokens = Dialogue(HistoryWindow(turns=100, tokens=100))
    for k in range(10):
        by_tokens.exchange("x" * 120, f"answer {k}")  # 30 + 3 estimated tokens a turn
    assert sum(estimated_tokens(m["content"]) for m in by_tokens.messages) <= 100
    assert len(by_tokens.messages) == 6 and by_tokens.messages[-1]["content"] == "answer 9"


def test_a_robot_line_said_alone_is_a_turn_and_a_window_of_zero_reads_nothing():
    dialogue = Dialogue(HistoryWindow(turns=2))
    dialogue.said("This is the lab.")
    dialogue.exchange("Who built it?", "Our students.")
    dialogue.said("Next, the workshop.")
    assert [m["content"] for m in dialogue.messages] == ["Who built it?", "Our students.",
                                                         "Next, the workshop."]
    silent = Dialogue(HistoryWindow(turns=0))
    silent.exchange("Hello", "Hi")
    assert silent.request("again").history == () and silent.total == 2


def test_serve_reads_the_window_and_records_each_message_once(serve_app):
    _, session = serve_app("run.record=true", "serve.history_turns=3")
    runner = session.run.runner
    seen = []
    plan = runner.planner.plan
    runner.planner.plan = lambda request: seen.append(len(request.history)) or plan(request)
    for k in range(8):
        session._say(f"Welcome to stop number {k}, the robot arm is over there.", None)
    assert seen == [0, 2, 4, 6, 6, 6, 6, 6]  # the window, not the whole conversation
    assert session.info()["history"] == {"turns": 3, "tokens": 2000}
    session.close()
    session.run.session.close()
    recording = read_recording(session.run.session.run_dir / "session.mcap")
    said = [payload for _, payload in recording[CHANNEL]]
    assert [m["index"] for m in said] == list(range(16))  # each message once, in order
    requests = [payload for _, payload in recording["/request"]]
    assert [r["history_messages"] for r in requests] == seen and all("history" not in r for r in requests)
    assert len({len(json.dumps(r)) for r in requests}) == 1  # same-length utterances: same-size records
