"""The JSON schema of every channel a session recording carries: field types for Foxglove and for the
tests that validate every message (tests/recording/test_schemas.py).

A field marked SESSION_TIME holds a time on the recording's one clock: seconds since the recording
opened, the same time base as the message log times. Writers hand the Recorder those fields as read from
the loop's clock (or, for a stream message's `t`, as stream time) and the Recorder puts them on session
time; every other time field is a duration or an offset from its turn's speech start ("_s" names).
"""

from __future__ import annotations

NUMBER, STRING, BOOLEAN, INTEGER = (
    {"type": "number"},
    {"type": "string"},
    {"type": "boolean"},
    {"type": "integer"},
)
SESSION_TIME = {
    "type": ["number", "null"],
    "x-session-time": True,
    "description": "session time: s since the recording opened (the log time's base)",
}
NUMBERS = {"type": "array", "items": NUMBER}
JOINTS = {
    "type": "array",
    "items": NUMBER,
    "minItems": 14,
    "maxItems": 14,
    "description": "rad, G1 arm order",
}


def optional(schema: dict) -> dict:
    return {"anyOf": [schema, {"type": "null"}]}


def obj(required: bool = True, **properties: dict) -> dict:
    """An object with exactly these typed fields (all present unless required=False)."""
    out = {"type": "object", "properties": properties, "additionalProperties": False}
    if required:
        out["required"] = sorted(properties)
    return out


def array(items: dict) -> dict:
    return {"type": "array", "items": items}


RECORD = obj(
    **{
        "class": STRING,
        "variant": optional(STRING),
        "intensity": INTEGER,
        "trigger": optional(STRING),
        "confidence": NUMBER,
    }
)
EVENT = obj(t=SESSION_TIME, kind=STRING, name=STRING, command_id=optional(INTEGER), detail=STRING)
TIMING = obj(
    times=NUMBERS,
    stroke=array(INTEGER),
    target_s=NUMBER,
    arrival_s=NUMBER,
    fit=STRING,
    blend_in=BOOLEAN,
    scale=NUMBER,
    cut=BOOLEAN,
)
TIMELINE_GESTURE = obj(
    k=INTEGER,
    motion=STRING,
    command_id=optional(INTEGER),
    keyframe=JOINTS,
    planned_s=optional(NUMBER),
    executed_s=optional(NUMBER),
    dropped=optional(STRING),
    trigger=optional(STRING),
    onset_s=optional(NUMBER),
)
JOINT_STATE = {
    **obj(t=SESSION_TIME, name=array(STRING), position=NUMBERS, velocity=NUMBERS, effort=NUMBERS),
    "description": "sensor_msgs/JointState: the robot's arm joints (Foxglove's URDF layer)",
}
POSE = obj(x=NUMBER, y=NUMBER, yaw_deg=NUMBER)

SCHEMAS: dict[str, dict] = {
    "/robot_description": obj(data={**STRING, "description": "URDF of the robot (Foxglove's URDF layer)"}),
    "/request": obj(utterance=STRING, history_messages=INTEGER, image=BOOLEAN),
    "/dialogue": {**obj(index=INTEGER, role=STRING, content=STRING), "description": "each message once"},
    "/planner_output": obj(
        raw=STRING, latency_s=NUMBER, fallback=BOOLEAN, error=optional(STRING), meta={"type": "object"}
    ),
    "/plan": obj(reply=STRING, source=STRING, notes=array(STRING), records=array(RECORD)),
    "/resolved": obj(
        resolved=array(
            obj(
                **{
                    "class": STRING,
                    "requested": optional(STRING),
                    "resolved": STRING,
                    "resolved_class": STRING,
                    "rule": STRING,
                    "confidence": NUMBER,
                }
            )
        )
    ),
    "/modulated": obj(
        modulated=array(obj(name=STRING, intensity=INTEGER, duration_s=NUMBER, keyframes=array(JOINTS)))
    ),
    "/speech": obj(
        text=STRING,
        duration_s=NUMBER,
        estimated=BOOLEAN,
        audio=optional(STRING),
        words=array(obj(text=STRING, char_start=INTEGER, start_s=NUMBER)),
    ),
    "/schedule": obj(
        preroll_s=NUMBER,
        releases=array(
            obj(
                name=STRING,
                intensity=INTEGER,  # as played: the softening policy may lower the planner's
                release_s=NUMBER,
                how=STRING,
                trigger_found=BOOLEAN,
                dropped=optional(STRING),
                timing=optional(TIMING),
            )
        ),
    ),
    "/submitted": obj(
        speech_start=SESSION_TIME,
        play_at=SESSION_TIME,
        submission_s=NUMBERS,
        commands=array(
            obj(
                id=INTEGER,
                record=optional(INTEGER),
                name=STRING,
                release_at=SESSION_TIME,
                duration_s=NUMBER,
                label=STRING,
            )
        ),
    ),
    "/dispatched": obj(completed=BOOLEAN, ticks=INTEGER, speech_start=SESSION_TIME, events=array(EVENT)),
    "/speech/timeline": obj(
        speech_start=SESSION_TIME,
        duration_s=NUMBER,
        text=STRING,
        preroll_s=NUMBER,
        words=array(obj(text=STRING, char_start=INTEGER, char_end=INTEGER, start_s=NUMBER)),
        gestures=array(TIMELINE_GESTURE),
    ),
    "/speech/said": {
        **obj(t=SESSION_TIME, text=STRING, duration_s=NUMBER, audio=BOOLEAN),
        "description": "each clip the player started, at its start (emopose/speech/audio_channel.py)",
    },
    "/speech/audio": {
        **obj(
            t=SESSION_TIME,
            offset_s={**NUMBER, "description": "s into its clip"},
            format={"type": "string", "enum": ["pcm-s16"]},
            sample_rate=INTEGER,
            number_of_channels=INTEGER,
            data={**STRING, "contentEncoding": "base64", "description": "little-endian PCM16 samples"},
        ),
        "description": "the spoken audio as heard, in chunks at their play-clock time (Foxglove RawAudio)",
    },
    "/sequencer/events": EVENT,
    "/joints/command": obj(t=SESSION_TIME, q=JOINTS),
    "/joints/sim": obj(t=SESSION_TIME, q=JOINTS),
    "/joints/torque": obj(t=SESSION_TIME, tau=JOINTS, ratio=NUMBER),
    "/joint_states": JOINT_STATE,
    "/g1/lowcmd": {
        **obj(
            required=False,
            q=JOINTS,
            weight=NUMBER,
            dq=JOINTS,
            tau=JOINTS,
            crc=INTEGER,
            phase=STRING,
            t=SESSION_TIME,
            clamped=BOOLEAN,
            reason=STRING,
        ),
        "required": ["q", "weight", "crc", "phase"],
    },
    "/g1/event": obj(event=STRING, reason=STRING, weight=NUMBER),
    "/base/odometry": POSE,
    "/base/true": POSE,
    "/tour/speech": obj(kind=STRING, text=STRING, duration_s=NUMBER),
    "/tour/event": {
        **obj(
            required=False,
            event=STRING,
            pose=POSE,
            goal=POSE,
            odometry=POSE,
            stop=STRING,
            reached=BOOLEAN,
            aborted=BOOLEAN,
            at_rest=BOOLEAN,
            text=STRING,
            where=STRING,
            base_moving=BOOLEAN,
            gestures=INTEGER,
            image=BOOLEAN,
            kind=STRING,
            speech_s=NUMBER,
            error_m=NUMBER,
        ),
        "required": ["event"],
    },
}


def session_time_paths(schema: dict, prefix: tuple[str, ...] = ()) -> list[tuple[str, ...]]:
    """Where a schema's SESSION_TIME fields lie in a message: key paths, "*" for every array item."""
    if schema.get("x-session-time"):
        return [prefix]
    paths = []
    for key, sub in schema.get("properties", {}).items():
        paths += session_time_paths(sub, (*prefix, key))
    for sub in schema.get("anyOf", []):
        paths += session_time_paths(sub, prefix)
    if "items" in schema:
        paths += session_time_paths(schema["items"], (*prefix, "*"))
    return paths
