"""Request bodies and WebSocket messages: validated once at the edge, with bounded sizes.

Every string and list has a maximum so a request can never make the server build something large;
motion names use the library's file-name pattern, so no name can point outside library/.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field

from emopose import CLASSES
from emopose.stages.parse import MAX_SPOKEN_CHARS
from emopose.studio.saving import NAME_PATTERN

MotionName = Annotated[str, Field(pattern=NAME_PATTERN, description="a library motion name")]
GestureClass = Literal[CLASSES]  # type: ignore[valid-type]
Keyframe = Annotated[list[float], Field(min_length=14, max_length=14)]
Intensity = Annotated[int, Field(ge=1, le=5, strict=True)]  # strict: "3" is refused, not coerced


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


class SayRequest(_Strict):
    text: str = Field(min_length=1, max_length=MAX_SPOKEN_CHARS)  # the input limit, in /api/info
    attach_camera: bool = Field(default=False, strict=True)  # send the camera frame with the turn


class GestureRequest(_Strict):
    name: MotionName
    intensity: Intensity = 3
    text: str | None = Field(default=None, max_length=500)  # an optional reply to speak with it


class ResolveRequest(_Strict):
    cls: GestureClass = Field(alias="class")
    variant: str | None = Field(default=None, max_length=64)


class DraftRequest(_Strict):
    keyframes: list[Keyframe] = Field(min_length=1, max_length=14)
    motion_type: Literal["sequence", "pose"] = "sequence"
    duration: float | None = Field(default=None, gt=0.0, le=20.0)  # None: Eq. duration
    stroke: tuple[int, int] | None = None  # sync points; None: the documented default (largest excursion)
    times: list[float] | None = Field(default=None, max_length=14)  # per keyframe; None: evenly spaced
    intensity: Intensity = 3


class PerformRequest(DraftRequest):
    model_config = ConfigDict(extra="forbid", populate_by_name=True, allow_inf_nan=False)

    cls: GestureClass = Field(default="neutral", alias="class")  # the label the sequencer shows


class PreviewRequest(DraftRequest):
    camera: Literal["front", "oblique", "side", "head"] = "front"
    frames: int | None = Field(default=None, ge=1, le=60)


class SaveRequest(_Strict):
    model_config = ConfigDict(extra="forbid", populate_by_name=True, allow_inf_nan=False)

    name: str = Field(min_length=1, max_length=64)  # checked against the pattern in saving.py (clear message)
    cls: GestureClass = Field(alias="class")
    description: str = Field(min_length=3, max_length=200)
    motion_type: Literal["sequence", "pose"] = "sequence"
    duration: float | None = Field(default=None, gt=0.0, le=20.0)
    stroke: tuple[int, int] | None = None
    times: list[float] | None = Field(default=None, max_length=14)
    keyframes: list[Keyframe] = Field(min_length=1, max_length=14)
    examples: list[str] | None = None  # utterances the local planner reads next to the description
    overwrite: bool = Field(default=False, strict=True)

    def motion(self) -> dict:
        """The library-file mapping (what MotionLibrary.save validates)."""
        data = self.model_dump(by_alias=True, exclude={"overwrite"}, exclude_none=True)
        return data


class CancelRequest(_Strict):
    turn: int | None = Field(default=None, ge=1, strict=True)  # the turn_started message's id; None: any


class RenameRequest(_Strict):
    new_name: str = Field(min_length=1, max_length=64)  # checked against the pattern in saving.py


# -- WebSocket, client -> server ---------------------------------------------------------------
class SayMessage(SayRequest):
    type: Literal["say"]


class GestureMessage(GestureRequest):
    type: Literal["gesture"]


class InterruptMessage(_Strict):
    type: Literal["interrupt"]


class CancelMessage(CancelRequest):
    type: Literal["cancel"]


class ListeningMessage(_Strict):
    type: Literal["listening"]
    active: bool = Field(default=True, strict=True)  # the visitor started (true) or gave up (false) a line


class PingMessage(_Strict):
    type: Literal["ping"]


ClientMessage = Annotated[SayMessage | GestureMessage | InterruptMessage | CancelMessage | ListeningMessage
                          | PingMessage,
                          Field(discriminator="type")]
