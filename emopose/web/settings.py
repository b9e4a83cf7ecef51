"""Serve settings (the `serve:` config block), validated once where they enter.

A non-loopback bind exposes the robot to the network, so it is refused without an access token;
the token is best passed through the environment (EMOPOSE_TOKEN), which keeps it out of the
command line and of Hydra's saved overrides.
"""

from __future__ import annotations

import ipaddress
import re
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

MIN_TOKEN_CHARS = 16
TOKEN_RE = re.compile(rf"[A-Za-z0-9._~-]{{{MIN_TOKEN_CHARS},256}}")


def is_loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False  # a DNS name other than localhost may resolve anywhere


class ServeSettings(BaseModel):
    model_config = ConfigDict(extra="forbid")

    host: str = "127.0.0.1"
    port: int = Field(8765, ge=1, le=65535)
    token: str | None = None
    max_body_bytes: int = Field(256 * 1024, ge=1024)  # JSON requests (a 14-keyframe motion is ~3 KiB)
    max_audio_bytes: int = Field(8 * 1024 * 1024, ge=1024)  # microphone uploads
    max_ws_message_bytes: int = Field(64 * 1024, ge=1024)
    state_hz: float = Field(20.0, gt=0, le=50)  # sequencer state + stick figure pushes
    sim_fps: float = Field(15.0, gt=0, le=60)  # MuJoCo frames when backend=mujoco
    camera_fps: float = Field(3.0, ge=0, le=30)  # 0 disables the camera panel
    camera: Literal["auto", "webcam", "sim", "off"] = "auto"  # auto: a webcam if OpenCV finds one, else sim
    webcam_index: int = 0
    sim_camera: str = "front"
    head_camera: str = "head"
    render_width: int = Field(320, ge=64, le=1920)
    render_height: int = Field(240, ge=48, le=1080)
    render_quality: Literal["fast", "full"] = "fast"  # fast: no MSAA/shadows (software EGL stays >= 10 fps)
    preview_frames: int = Field(12, ge=1, le=60)  # Pose Studio MuJoCo preview frames per request
    max_turns_kept: int = Field(100, ge=1)  # the page's log; results count every turn (turns.jsonl)
    max_clients: int = Field(16, ge=1, le=10_000)  # pages open at once; one more is closed with code 1013
    push_budget_hz: float = Field(400.0, gt=0)  # WebSocket pushes a second, all pages together
    min_push_hz: float = Field(1.0, gt=0, le=50)  # the slowest a busy or slow page is pushed to
    history_turns: int = Field(12, ge=0)  # the dialogue window planners read (emopose/turn/dialogue.py)
    history_tokens: int = Field(2000, ge=0)  # estimated tokens (characters / 4) in that window

    @model_validator(mode="after")
    def _token_for_network(self) -> ServeSettings:
        if self.token is not None and not self.token.strip():
            self.token = None
        if not is_loopback(self.host) and self.token is None:
            raise ValueError(
                f"serve.host={self.host} is reachable from the network: set an access token "
                "(EMOPOSE_TOKEN=... or serve.token=...), or keep serve.host=127.0.0.1")
        if self.token is not None and not TOKEN_RE.fullmatch(self.token):
            # It travels in a cookie and a query string: keep it to URL-safe characters.
            raise ValueError(f"serve.token must be at least {MIN_TOKEN_CHARS} URL-safe characters "
                             "(letters, digits, - _ . ~), "
                             "e.g. python -c 'import secrets; print(secrets.token_urlsafe())'")
        return self

    @classmethod
    def from_config(cls, serve: dict) -> ServeSettings:
        """The `serve:` block validated; a bad value is a ValueError that names the key and what to do."""
        try:
            return cls.model_validate(serve)
        except ValidationError as exc:
            raise ValueError("; ".join(_problem(e) for e in exc.errors())) from None

    @property
    def local_only(self) -> bool:
        return is_loopback(self.host)


def _problem(error: dict) -> str:
    """One pydantic error as a person reads it: 'serve.port: ...', or a model check's own message."""
    where = ".".join(map(str, error["loc"]))
    message = error["msg"].removeprefix("Value error, ")
    return f"serve.{where}: {message}" if where else message
