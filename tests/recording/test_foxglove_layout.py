"""docs/foxglove/layout.json against a real session recording, since Foxglove itself cannot run here.

Every panel's topic must exist in the file with the schema the panel reads: the 3D panel's URDF layer a
std_msgs/String whose `data` is the URDF (its follow frame a link of it), moved by joint states (a
sensor_msgs/JointState naming the URDF's joints, which Foxglove's layer uses only with controlMode
`jointStates`); each plotted path a number in every message; the raw-message panels' topics present.
The layer's keys are those of Foxglove's layout schema (foxglove-sdk, foxglove.layouts).
"""

from __future__ import annotations

import json
import re
import xml.etree.ElementTree as ET
from pathlib import Path

from mcap.reader import make_reader

LAYOUT = Path(__file__).resolve().parents[2] / "docs" / "foxglove" / "layout.json"
# Foxglove accepts a ROS datatype under each of these spellings (addRosDataType in its 3D panel).
STRING = {"std_msgs/String", "std_msgs/msg/String", "ros.std_msgs.String"}
JOINT_STATE = {"sensor_msgs/JointState", "sensor_msgs/msg/JointState", "ros.sensor_msgs.JointState"}
URDF_LAYER_KEYS = {
    "layerId", "instanceId", "label", "order", "visible", "frameLocked", "sourceType", "url", "filePath",
    "parameter", "topic", "framePrefix", "controlMode", "jointStatesTopic", "displayMode", "fallbackColor",
    "showAxis", "axisScale", "showOutlines", "opacity", "links",
}
INDEXED_PATH = re.compile(r"^(/[^.\[]+)\.(\w+)\[(\d+)\]$")  # /topic.field[index], as the plot uses


def _channels(path: Path) -> dict[str, tuple[str, dict, list[dict]]]:
    """topic -> (schema name, schema, payloads), read with the official mcap reader."""
    found: dict[str, tuple[str, dict, list[dict]]] = {}
    with path.open("rb") as f:
        for schema, channel, message in make_reader(f).iter_messages(log_time_order=True):
            entry = found.setdefault(channel.topic, (schema.name, json.loads(schema.data), []))
            entry[2].append(json.loads(message.data))
    return found


def _leaves(node) -> list[str]:
    return [node] if isinstance(node, str) else [*_leaves(node["first"]), *_leaves(node["second"])]


def _check_urdf_layer(layer: dict, follow: str, channels) -> None:
    unknown = layer.keys() - URDF_LAYER_KEYS
    assert not unknown, f"keys Foxglove's URDF layer does not know: {unknown}"
    assert layer["layerId"] == "foxglove.Urdf" and layer["sourceType"] == "topic"
    name, schema, descriptions = channels[layer["topic"]]
    assert name in STRING and schema["properties"]["data"]["type"] == "string", name
    urdf = ET.fromstring(descriptions[0]["data"])
    links = {link.get("name") for link in urdf.iter("link")}
    movable = [j.get("name") for j in urdf.iter("joint") if j.get("type") != "fixed"]
    assert follow in links, f"followTf {follow!r} is not a URDF link"
    assert layer.get("controlMode") == "jointStates", "without it the layer ignores the joint states"
    name, schema, states = channels[layer["jointStatesTopic"]]
    assert name in JOINT_STATE, name
    assert schema["properties"]["name"]["type"] == schema["properties"]["position"]["type"] == "array"
    for state in states:
        assert state["name"] == movable and len(state["position"]) == len(movable)


def _check_plot(config: dict, channels) -> None:
    for series in config["paths"]:
        topic, field, index = INDEXED_PATH.match(series["value"]).groups()
        assert topic in channels, topic
        for payload in channels[topic][2]:
            value = payload[field][int(index)]
            assert isinstance(value, int | float) and not isinstance(value, bool), series["value"]
        if "name" in channels[topic][2][0]:  # a label naming the joint names the one at that index
            joint = channels[topic][2][0]["name"][int(index)]
            assert series["label"].split(",")[0].replace(" ", "_") in joint, (series["label"], joint)


def test_every_panel_reads_a_recorded_topic_with_its_schema(session_recording):
    layout = json.loads(LAYOUT.read_text())
    channels = _channels(session_recording)
    panels = layout["configById"]
    assert sorted(_leaves(layout["layout"])) == sorted(panels), "a panel without config, or config unused"
    kinds = {panel_id.split("!")[0] for panel_id in panels}
    assert kinds == {"3D", "Plot", "RawMessages"}, kinds
    for panel_id, config in panels.items():
        kind = panel_id.split("!")[0]
        if kind == "3D":
            layers = {key: layer for key, layer in config["layers"].items()
                      if layer["layerId"] == "foxglove.Urdf"}
            assert layers, "the 3D panel shows no robot"
            for key, layer in layers.items():
                assert layer.get("instanceId", key) == key
                _check_urdf_layer(layer, config["followTf"], channels)
        elif kind == "Plot":
            _check_plot(config, channels)
        else:
            topic = config["topicPath"]
            assert topic in channels and channels[topic][1].get("properties"), topic
