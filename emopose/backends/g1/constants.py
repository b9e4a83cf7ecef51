"""DDS topic names, service names and RPC codes of the G1 as used by this backend.

All figures come from shared/reference/g1.md; motor indices, joint limits and the control period
are the robot's facts and live in emopose.robot.g1_spec. Kept free of heavy imports so config
tests and the backend constructor can use them without cyclonedds installed.
"""

TOPIC_ARM_SDK = "rt/arm_sdk"
TOPIC_LOWSTATE = "rt/lowstate"

# Firmware ai_sport >= 8.2.0.0 serves locomotion as "sport"; older firmware used "loco".
LOCO_SERVICE = "sport"
LOCO_API_GET_FSM_ID = 7001
LOCO_API_SET_FSM_ID = 7101
LOCO_API_SET_VELOCITY = 7105

# Unitree's RPC status codes (unitree_sdk2py/rpc/internal.py) that the fake server answers with.
RPC_OK = 0
RPC_ERR_SERVER_API_NOT_IMPL = 3203
RPC_ERR_SERVER_API_PARAMETER = 3204

def request_topic(service: str) -> str:
    return f"rt/api/{service}/request"


def response_topic(service: str) -> str:
    return f"rt/api/{service}/response"
