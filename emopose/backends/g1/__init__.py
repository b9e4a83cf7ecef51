"""Physical Unitree G1 backend over DDS (Cyclone DDS 0.10.2, the robot's version).

Modules, data path order: settings (config validation) -> backend (G1Backend) -> lifecycle (ArmState
and every transition) -> handover (weight ramps, release) -> output (every LowCmd_ out, paced and
recorded) -> link (DDS participant, rt/lowstate monitor, rt/arm_sdk writer) -> arm_command (LowCmd_
build) -> wire + crc (packed C layout, CDR bytes, CRC); supervisor (watchdog, release on faults);
profiles (weight ramps, blends); release (the release plan, its per-tick bound); torso (gravity under
the measured torso); loco (LocoClient RPC); hg_types/api_types (IDL). The fake G1 for
tests and benchmarks lives in emopose.testing.

The names below are loaded on first use (PEP 562), and no module of this package imports the
package itself: importing it costs nothing, runs no import cycle and never imports cyclonedds
(connect()/open() do).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

_HOME = {
    "G1Backend": "backend",
    "G1BackendError": "errors",
    "G1ConnectionError": "errors",
    "LocoError": "errors",
    "LocoTimeoutError": "errors",
    "LocoClient": "loco",
}
__all__ = [
    "G1Backend",
    "G1BackendError",
    "G1ConnectionError",
    "LocoClient",
    "LocoError",
    "LocoTimeoutError",
]

if TYPE_CHECKING:
    from emopose.backends.g1.backend import G1Backend
    from emopose.backends.g1.errors import (
        G1BackendError,
        G1ConnectionError,
        LocoError,
        LocoTimeoutError,
    )
    from emopose.backends.g1.loco import LocoClient


def __getattr__(name: str) -> object:
    if name not in _HOME:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{_HOME[name]}"), name)
