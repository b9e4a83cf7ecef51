"""EmoPose: a language model chooses what the robot communicates; the robot owns every joint value."""

import os

# litellm fetches a price map over the network at import unless told otherwise; we run offline.
os.environ.setdefault("LITELLM_LOCAL_MODEL_COST_MAP", "True")

CLASSES: tuple[str, ...] = (
    "pointing",
    "emphasizing",
    "rejecting",
    "agreeing",
    "doubting",
    "welcoming",
    "comforting",
    "neutral",
)
NUM_JOINTS = 14
CONTROL_HZ = 50.0
CONTROL_DT = 1.0 / CONTROL_HZ
