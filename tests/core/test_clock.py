"""run.clock picks the clock: auto | monotonic | virtual; anything else is a config error, and a real robot
never runs on virtual time. Callers read `clock.realtime`, never the clock's class."""

from __future__ import annotations

import pytest

from emopose.build import ConfigError, build_run
from emopose.clock import FakeClock, MonotonicClock, clock_for


@pytest.mark.parametrize("setting, robot, realtime", [
    ("auto", False, False), ("auto", True, True), ("monotonic", False, True), ("monotonic", True, True),
    ("virtual", False, False)])
def test_each_setting_gives_the_clock_it_names(setting, robot, realtime):
    clock = clock_for(setting, backend_needs_realtime=robot)
    assert clock.realtime is realtime
    assert isinstance(clock, MonotonicClock if realtime else FakeClock)


def test_virtual_time_is_refused_for_a_real_robot():
    with pytest.raises(ValueError, match="real robot"):
        clock_for("virtual", backend_needs_realtime=True)


def test_a_wrong_value_is_a_config_error_not_virtual_time(compose, tmp_path):
    with pytest.raises(ConfigError, match=r"run.clock='fake'.*auto, monotonic, virtual"):
        build_run(compose("planner=keyword", "run.clock=fake"), tmp_path)
