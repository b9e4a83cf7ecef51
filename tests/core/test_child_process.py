"""emopose.child_process: answers, exceptions, stdout noise, a hung child and a dead one."""

from __future__ import annotations

import pytest

from emopose.child_process import ChildProcess, ChildProcessGone


@pytest.fixture
def echo():
    child = ChildProcess("tests.core.child_helpers", "serve_echo", name="echo")
    assert child.receive(30) is None  # built
    yield child
    child.close()


def test_answers_and_exceptions_cross_the_pipe(echo):
    assert echo.request(("echo", {"q": [1.0, 2.0]})) == {"q": [1.0, 2.0]}
    with pytest.raises(ValueError, match="bad pose"):
        echo.request(("raise", "bad pose"))
    assert echo.request(("echo", 7)) == 7  # the child survives a failed request


def test_printing_in_the_child_does_not_corrupt_answers(echo):
    assert [echo.request(("print", i)) for i in range(3)] == [0, 1, 2]


def test_a_child_that_does_not_answer_in_time_is_killed(echo):
    with pytest.raises(ChildProcessGone, match="did not answer within 0.2 s"):
        echo.request(("sleep", 5.0), timeout_s=0.2)
    assert not echo.alive or echo.process.wait(5) is not None
    with pytest.raises(ChildProcessGone):
        echo.request(("echo", 1))


def test_a_dead_child_is_reported(echo):
    with pytest.raises(ChildProcessGone, match="exited"):
        echo.request(("exit", None))
    assert not echo.alive


def test_a_failed_start_raises_its_cause():
    child = ChildProcess("tests.core.child_helpers", "serve_broken", name="broken")
    with pytest.raises(OSError, match="no EGL here"):
        child.receive(30)
    child.close()
