"""Streamed turns (#17 item 6) against the local streaming server: a reply spoken sentence by sentence
while the model writes, on a FakeClock (virtual time); the server's counters say what it sent."""

from __future__ import annotations

import threading
import time

import pytest
from fake_answers import http_error
from fake_stream import runaway, streamed, tokens

from emopose.execution.sequencer import State
from emopose.planners.baselines.keyword import KeywordPlanner
from emopose.planners.chat.annotate import AnnotatePlanner
from emopose.recording import read_recording
from tests.wiring import wire

REPLY = ("Welcome to the lab! The charging dock is over there, by the window. "
         "No, please do not touch the robot arm. It is calibrating.")
SENTENCES = ["Welcome to the lab!", "The charging dock is over there, by the window.",
             "No, please do not touch the robot arm.", "It is calibrating."]
FIRST = len(tokens(SENTENCES[0])) + 1  # the next token's leading space shows the first sentence ended


@pytest.fixture
def wired(writable_library, make_chat, tmp_path):
    # the first streamed call in a process loads litellm's streaming parts: seconds on a loaded machine,
    # which the 5 s deadline of the other planner tests would count against the answer
    planner = make_chat(AnnotatePlanner, "prompts/annotate.md", annotator=KeywordPlanner(), stream=True,
                        cache=False, max_retries=0, max_sentences=len(SENTENCES), timeout_s=30.0)
    built = wire(writable_library, tmp_path / "run", planner=planner, mode="timeline")
    with built.session:
        yield built


def test_the_recording_holds_every_sentence_as_a_turn(fake_openai, wired, tmp_path):
    fake_openai.default = streamed(REPLY)
    wired.runner.run_streamed("Where can I charge my phone?")
    wired.session.close()
    recording = read_recording(tmp_path / "run" / "session.mcap")
    assert [m["reply"] for _, m in recording["/plan"]] == SENTENCES
    assert len(recording["/dispatched"]) == len(recording["/planner_output"]) == 4


def test_sentences_are_performed_in_order_and_each_clip_starts_where_the_last_ended(fake_openai, wired):
    fake_openai.default = streamed(REPLY)
    reply = wired.runner.run_streamed("Hello! Where can I charge my phone?")
    assert [t.plan.reply for t in reply.turns] == SENTENCES and reply.error is None and not reply.cancelled
    starts = [t.dispatched.speech_start for t in reply.turns]
    ends = [s + t.speech.duration_s for s, t in zip(starts, reply.turns)]
    assert starts[1:] == pytest.approx(ends[:-1])  # seamless, on virtual time
    assert {"pointing", "rejecting"} <= {r.cls for t in reply.turns for r in t.plan.records}
    assert fake_openai.requests[0]["stream"] is True
    assert reply.turns[0].schedule.preroll_s == 0.0  # planner.stream_preroll_s: the first words never wait
    assert wired.runner.dialogue.messages[-1] == {"role": "assistant", "content": REPLY}
    assert wired.sequencer.settled() and wired.sequencer.state == State.IDLE  # waited once, at the end


def test_each_sentences_gestures_are_released_against_its_own_speech(fake_openai, wired):
    fake_openai.default = streamed(REPLY)
    turn = wired.runner.run_streamed("Where can I charge my phone?").turns[1]
    (command,) = turn.submitted.commands
    release = turn.schedule.releases[command.record].release_s
    strokes = [e for e in wired.sequencer.events.since(0)
               if e.kind == "stroke" and e.command_id == command.id]
    assert turn.dispatched.speech_start > turn.submitted.speech_start  # it waited for the first sentence
    assert strokes and strokes[0].t >= turn.dispatched.speech_start + release


def test_speech_starts_before_the_model_finishes(fake_openai, wired):
    hold, seen = threading.Event(), []
    fake_openai.default = streamed(REPLY, hold=hold, hold_after=FIRST)

    def first_spoken(turn):
        seen.append((fake_openai.tokens_sent, turn.dispatched.speech_start))
        hold.set()  # only now may the model write on

    reply = wired.runner.run_streamed("Where can I charge my phone?", on_turn=first_spoken)
    assert seen[0][0] <= FIRST < len(tokens(REPLY)) and seen[0][1] is not None
    assert len(reply.turns) == 4


def test_an_interrupt_cancels_the_stream_and_the_server_sees_it_closed(fake_openai, wired):
    hold = threading.Event()
    fake_openai.default = streamed(REPLY, tokens_per_s=50, hold=hold, hold_after=FIRST)

    def interrupt(turn):
        wired.runner.cancel()  # what the web UI's interrupt does, then the sequencer's interrupt
        wired.sequencer.interrupt([], now=wired.loop.clock.now())
        hold.set()

    reply = wired.runner.run_streamed("Where can I charge my phone?", on_turn=interrupt)
    assert reply.cancelled and [t.plan.reply for t in reply.turns] == SENTENCES[:1]
    assert wired.runner.dialogue.messages[-1]["content"] == SENTENCES[0]
    for _ in range(500):  # the server finds out at its next write but one (the peer's reset comes between)
        if fake_openai.streams_dropped or fake_openai.answered:
            break
        time.sleep(0.01)
    assert fake_openai.streams_dropped == 1 and fake_openai.tokens_sent < len(tokens(REPLY))


def test_a_server_dying_mid_stream_stops_safely_with_what_was_said(fake_openai, wired):
    fake_openai.default = streamed(REPLY, die_after=FIRST + 2)
    reply = wired.runner.run_streamed("Where can I charge my phone?")
    assert [t.plan.reply for t in reply.turns] == SENTENCES[:1]
    assert "stopped after 1 sentence" in reply.error and not reply.cancelled
    assert reply.turns[0].dispatched.speech_start is not None
    assert wired.sequencer.settled() and wired.sequencer.state == State.IDLE  # its gestures ran to rest


def test_a_stream_refused_before_its_first_sentence_falls_back_as_an_unstreamed_turn_does(fake_openai, wired):
    fake_openai.default = http_error(401)
    reply = wired.runner.run_streamed("Where can I charge my phone?")
    (turn,) = reply.turns
    assert turn.planner_output.fallback and turn.plan.source == "call_failed" and reply.error is None


def test_the_preset_streams_on_request(compose):
    planner = compose("planner=annotate", "planner.stream=true").planner
    assert planner.stream is True and planner.stream_preroll_s == 0.0


def test_a_runaway_reply_ends_at_its_bound_and_the_stream_is_closed(fake_openai, wired):
    fake_openai.default = runaway(sentences=60)  # about three minutes of speech if let run
    bound = wired.runner.planner.bound
    bound.max_sentences, bound.max_speech_s = 3, 60.0  # planner.max_sentences, planner.max_speech_s
    reply = wired.runner.run_streamed("Tell me about the lab.")
    said = [t.plan.reply for t in reply.turns]
    assert said == [f"This is sentence number {k} of a reply that goes on and on." for k in range(3)]
    for _ in range(500):  # the server finds out at its next write but one
        if fake_openai.streams_dropped:
            break
        time.sleep(0.01)
    assert fake_openai.streams_dropped == 1 and fake_openai.tokens_sent < len(tokens(runaway(60).content))
