"""Topic names, motor indices and wire constants of the G1 (29-DoF) as used by this backend.

All figures come from shared/reference/g1.md. Kept free of heavy imports so config tests and the
backend constructor can use them without cyclonedds installed.
"""

NUM_MOTORS = 35
ARM_MOTORS = tuple(range(15, 29))  # 15-21 left arm, 22-28 right arm, the library's joint order
WAIST_MOTORS = (12, 13, 14)  # waist yaw, roll, pitch
WEIGHT_MOTOR = 29  # motor_cmd[29].q in [0, 1]: how much the firmware blends in the arm_sdk targets

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

CONTROL_DT = 0.02  # arm_sdk period used by Unitree's own arm example and by our sequencer


def request_topic(service: str) -> str:
    return f"rt/api/{service}/request"


def response_topic(service: str) -> str:
    return f"rt/api/{service}/response"
