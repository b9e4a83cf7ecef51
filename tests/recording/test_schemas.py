"""Foxglove-ready recordings: every channel of a real session has a typed JSON schema and every message
validates against it; the arms move by joint name on /joint_states, the robot's URDF is in the file."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import jsonschema

from emopose.robot.g1_spec import JOINT_NAMES
from tests.recording.conftest import every_message


def test_every_message_validates_against_its_typed_schema(session_recording):
    messages = every_message(session_recording)
    validators = {}
    for topic, schema, _, payload in messages:
        if topic not in validators:
            assert schema.get("properties"), f"{topic}: a bare schema {schema}"
            jsonschema.Draft202012Validator.check_schema(schema)
            validators[topic] = jsonschema.Draft202012Validator(schema)
        errors = [e.message for e in validators[topic].iter_errors(payload)]
        assert not errors, f"{topic}: {errors[:3]}"
    assert {"/robot_description", "/joint_states", "/joints/command", "/speech/timeline"} <= set(validators)


def test_joint_states_name_the_urdf_joints(session_recording):
    messages = every_message(session_recording)
    urdf = next(p["data"] for topic, _, _, p in messages if topic == "/robot_description")
    revolute = [j.get("name") for j in ET.fromstring(urdf).iter("joint") if j.get("type") == "revolute"]
    states = [p for topic, _, _, p in messages if topic == "/joint_states"]
    assert states and revolute == list(JOINT_NAMES)
    for state in states:
        assert state["name"] == revolute and len(state["position"]) == len(state["velocity"]) == 14
