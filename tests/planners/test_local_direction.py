"""Spatial words decide the pointing motion (planners/local/direction.py), in both frames."""

import pytest

from emopose.planners.local.direction import direction_of, pointing_motion

MOTIONS = {"left": "point_left", "right": "point_forward_right", "up": "point_up",
           "down": "point_forward_right", "behind": "point_forward_right", "here": "point_forward_right",
           "there": "point_forward_right", "this": "point_forward_right", "you": "point_forward_right",
           "me": "point_to_self"}
POINTING = frozenset({"point_left", "point_forward_right", "point_up", "point_to_self"})


@pytest.mark.parametrize(("text", "direction"), [
    ("the lockers on your left", "left"),
    ("Over there on the left you can see the lathe", "left"),
    ("turn right at the fountain", "right"),
    ("the right-hand door", "right"),
    ("the stairs up to the gallery", "up"),
    ("the lamp hanging above the stage", "up"),
    ("the cables running down to the basement", "down"),
    ("the crates behind the forklift", "behind"),
    ("right here on the bench", "here"),
    ("the red valve over there", "there"),
    ("this panel with the dials", "this"),
    ("the form in front of you", "you"),
    ("hand that one to me", "there"),  # deixis outranks the speaker
    ("follow me", "me"),
    ("I left my keys on the counter", None),  # "left" as a verb names no side
    ("right away, please", None),
])
def test_every_direction_word(text, direction):
    assert direction_of(text) == direction


def test_the_listener_s_side_is_mirrored_only_when_the_robot_faces_them():
    assert direction_of("the exit on your left", "shared") == "left"
    assert direction_of("the exit on your left", "facing") == "right"
    assert direction_of("the exit on your right", "facing") == "left"
    assert direction_of("the exit on my left", "facing") == "left"  # the speaker's own side
    assert direction_of("the exit on the left", "facing") == "left"


def test_the_strongest_cue_of_trigger_and_act_decides_and_the_motion_must_be_a_library_pointing_motion():
    # a trigger cut short of its side still points that way; "above" outranks "floor"
    texts = ("The office is down the", "The office is down the hall on the left")
    assert pointing_motion(texts, MOTIONS, POINTING) == "point_left"
    assert pointing_motion(("Her office is on the floor", "Her office is on the floor above"), MOTIONS,
                           POINTING) == "point_up"
    assert pointing_motion(("up on the shelf", "by the door"), MOTIONS, POINTING) == "point_up"
    assert pointing_motion(("the box", "the box on your left"), MOTIONS, POINTING) == "point_left"
    assert pointing_motion(("the box",), MOTIONS, POINTING) is None  # no direction: the chosen motion stays
    assert pointing_motion(("on your left",), MOTIONS, frozenset({"point_up"})) is None  # not in the library


def test_a_side_named_in_the_act_beats_plain_deixis_in_the_trigger():
    texts = ("over there", "The coats go over there, on your left")
    assert pointing_motion(texts, MOTIONS, POINTING) == "point_left"
    assert direction_of("the one up ahead") == "there" or direction_of("the one up ahead") is None
