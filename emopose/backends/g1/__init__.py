"""Physical Unitree G1 backend over DDS (Cyclone DDS 0.10.2, the robot's version).

Modules, data path order: settings (config validation) -> backend (G1Backend state machine) ->
link (DDS participant, rt/lowstate monitor, rt/arm_sdk writer) -> arm_command (LowCmd_ build) ->
wire + crc (packed C layout, CDR bytes, CRC); supervisor (watchdog, release on faults);
profiles (weight ramps, blends); loco (LocoClient RPC); hg_types/api_types (IDL);
fake_robot + fake_loco (a fake G1 process for tests and benchmarks).
Importing this package does not import cyclonedds; connect()/open() do.
"""

from emopose.backends.g1.backend import G1Backend
from emopose.backends.g1.errors import (
    G1BackendError,
    G1ConnectionError,
    LocoError,
    LocoTimeoutError,
)
from emopose.backends.g1.loco import LocoClient

__all__ = [
    "G1Backend",
    "G1BackendError",
    "G1ConnectionError",
    "LocoClient",
    "LocoError",
    "LocoTimeoutError",
]
