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
# A gesture's stroke has arrived when every joint is within this many rad of its stroke-start keyframe:
# where the timeline aims, what the sequencer reports as "stroke" and what sync_eval measures.
STROKE_TOLERANCE = 0.05
# Re-exported so `from emopose import CONTROL_DT` keeps working; the G1 spec module owns them.
from emopose.robot.g1_spec import CONTROL_DT, CONTROL_HZ, NUM_JOINTS  # noqa: E402

__all__ = ["CLASSES", "CONTROL_DT", "CONTROL_HZ", "NUM_JOINTS", "STROKE_TOLERANCE"]
