"""Tour scenario files: the lab tour loads; bad files are refused naming file, stop and field."""

from __future__ import annotations

import copy

import pytest
import yaml

from emopose.tour.job import TourJob
from emopose.tour.scenario import TourConfigError
from emopose.tour.scenario_loading import load_tour, parse_tour
from tests.tour.tour_helpers import LAB_FILE, lab_raw, small


def write(tmp_path, raw) -> str:
    path = tmp_path / "my_tour.yaml"
    path.write_text(yaml.safe_dump(raw, sort_keys=False))
    return str(path)


def refused(tmp_path, raw) -> str:
    with pytest.raises(TourConfigError) as err:
        load_tour(write(tmp_path, raw))
    return str(err.value)


def test_lab_tour_has_four_stops_in_route_order():
    spec = load_tour(LAB_FILE)
    assert [s.name for s in spec.stops_in_order] == [
        "introduction_board", "motion_capture", "autonomous_vehicles", "legged_robots"]
    assert spec.navigation.max_vx <= 0.3 and spec.navigation.stop_tolerance_m == pytest.approx(0.10)
    assert all(2 <= s.narration.count(".") + s.narration.count("!") <= 4 for s in spec.stops)
    assert {i.at_stop or i.during_leg for i in spec.interruptions} <= {s.name for s in spec.stops}


def test_missing_field_names_the_file_the_stop_and_the_field(tmp_path):
    raw = lab_raw()
    del raw["stops"][1]["pose"]["x"]
    message = refused(tmp_path, raw)
    assert "my_tour.yaml" in message
    assert "stops[1] 'motion_capture'.pose.x: Field required" in message


def test_missing_narration_and_misspelt_field(tmp_path):
    raw = small()
    del raw["stops"][0]["narration"]
    raw["stops"][1]["narations"] = "typo"
    message = refused(tmp_path, raw)
    assert "stops[0] 'first'.narration: Field required" in message
    assert "stops[1] 'second'.narations: Extra inputs are not permitted" in message


def test_unknown_route_target_is_named(tmp_path):
    message = refused(tmp_path, small(route=["first", "cafeteria"]))
    assert "route[1] = 'cafeteria' is not a stop; stops are ['first', 'second']" in message


def test_unknown_interruption_stop_and_pointing_target(tmp_path):
    raw = small(interruptions=[{"at_stop": "kitchen", "text": "Hi?"}])
    raw["stops"][0]["point_at"] = "green_box"
    message = refused(tmp_path, raw)
    assert "interruptions[0].at_stop = 'kitchen' is not a stop" in message
    assert "stops[0] 'first'.point_at = 'green_box' is not one of its objects ['red_box']" in message


def test_interruption_needs_exactly_one_place(tmp_path):
    message = refused(tmp_path,
                      small(interruptions=[{"at_stop": "first", "during_leg": "second", "text": "?"}]))
    assert "interruptions[0]" in message and "exactly one of at_stop or during_leg" in message


def test_stop_outside_the_arena_is_unreachable(tmp_path):
    raw = small()
    raw["stops"][1]["pose"]["y"] = 2.4  # arena y up to 2.5, robot radius 0.3
    message = refused(tmp_path, raw)
    assert "stops[1] 'second'.pose (0.6, 2.4) is unreachable: outside the arena" in message


def test_stop_inside_an_object_or_a_leg_through_one_is_blocked(tmp_path):
    raw = small()
    raw["stops"][0]["pose"].update(x=1.6, y=-0.4)
    message = refused(tmp_path, raw)
    assert "stops[0] 'first'.pose (1.6, -0.4) is blocked: within 0.3 m of object 'red_box'" in message
    raw = small()
    raw["stops"][0]["objects"][0]["position"] = [0.3, 0.0, 1.0]  # sits on the first leg
    assert "the straight leg to 'first' is blocked by object 'red_box'" in refused(tmp_path, raw)


def test_indoor_speed_limit_and_line_length(tmp_path):
    raw = small(navigation={"max_vx": 0.5}, closing="x" * 201)
    message = refused(tmp_path, raw)
    assert "navigation.max_vx: Input should be less than or equal to 0.3" in message
    assert "closing: String should have at most 200 characters" in message


def test_not_a_mapping_and_unreadable_file(tmp_path):
    with pytest.raises(TourConfigError, match="must be a mapping"):
        parse_tour(["a", "b"], "x.yaml")
    with pytest.raises(TourConfigError, match="cannot be read"):
        load_tour(tmp_path / "missing.yaml")


def test_job_without_a_scenario_says_how_to_give_one():
    with pytest.raises(TourConfigError, match="job.tour_file"):
        TourJob().load()


def test_job_names_the_conf_file_of_the_composed_tour():
    raw = copy.deepcopy(lab_raw())
    raw["stops"][0]["pose"]["yaw_deg"] = "east"
    with pytest.raises(TourConfigError,
                       match=r"conf/tour/lab.yaml: stops\[0\] 'introduction_board'.pose.yaw_deg"):
        TourJob(tour=raw).load()
