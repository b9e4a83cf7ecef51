"""Our CDR bytes against the cyclonedds 0.10.2 serializer, and the IDL types' wire identity."""

from __future__ import annotations

import numpy as np
import pytest

from emopose.backends.g1 import wire

pytest.importorskip(
    "cyclonedds.domain", reason="cyclonedds is not importable: run .ci/install_cyclonedds.sh"
)

from emopose.backends.g1.api_types import Request_, Response_
from emopose.backends.g1.hg_types import IMUState_, LowCmd_, LowState_, MotorCmd_, MotorState_


def f32(rng) -> float:
    return float(np.float32(rng.normal()))


def random_lowcmd(rng) -> LowCmd_:
    motors = [
        MotorCmd_(
            int(rng.integers(256)),
            f32(rng),
            f32(rng),
            f32(rng),
            f32(rng),
            f32(rng),
            int(rng.integers(2**32)),
        )
        for _ in range(35)
    ]
    return LowCmd_(1, 2, motors, rng.integers(2**32, size=4).tolist(), int(rng.integers(2**32)))


def random_lowstate(rng) -> LowState_:
    imu = IMUState_(
        [f32(rng) for _ in range(4)],
        [f32(rng) for _ in range(3)],
        [f32(rng) for _ in range(3)],
        [f32(rng) for _ in range(3)],
        int(rng.integers(-300, 300)),
    )
    motors = [
        MotorState_(
            int(rng.integers(256)),
            f32(rng),
            f32(rng),
            f32(rng),
            f32(rng),
            rng.integers(-100, 100, size=2).tolist(),
            f32(rng),
            rng.integers(2**32, size=2).tolist(),
            int(rng.integers(2**32)),
            rng.integers(2**32, size=4).tolist(),
        )
        for _ in range(35)
    ]
    return LowState_(
        rng.integers(2**32, size=2).tolist(),
        3,
        4,
        int(rng.integers(2**32)),
        imu,
        motors,
        rng.integers(256, size=40).tolist(),
        rng.integers(2**32, size=4).tolist(),
        int(rng.integers(2**32)),
    )


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_lowcmd_bytes_match_the_library(seed):
    msg = random_lowcmd(np.random.default_rng(seed))
    lib = msg.serialize()
    record = wire.lowcmd_from_cdr(lib)
    assert wire.lowcmd_to_cdr(record) == lib
    assert record["motor_cmd"]["q"].tolist() == [m.q for m in msg.motor_cmd]
    assert int(record["crc"]) == msg.crc
    back = LowCmd_.deserialize(wire.lowcmd_to_cdr(record))
    assert back == msg


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_lowstate_bytes_match_the_library(seed):
    msg = random_lowstate(np.random.default_rng(seed))
    record = wire.lowstate_from_cdr(msg.serialize())
    back = LowState_.deserialize(wire.lowstate_to_cdr(record))
    back.wireless_remote = list(back.wireless_remote)  # the library reads uint8[40] back as bytes
    assert back == msg
    assert record["motor_state"]["q"][15:29].tolist() == [m.q for m in msg.motor_state[15:29]]
    assert record["imu_state"]["temperature"] == msg.imu_state.temperature


def test_big_endian_or_truncated_payloads_are_rejected():
    lib = LowCmd_().serialize()
    assert wire.lowcmd_from_cdr(b"\x00\x00" + lib[2:]) is None
    assert wire.lowcmd_from_cdr(lib[:500]) is None


def test_type_names_field_order_and_final():
    expected = {
        LowCmd_: ["mode_pr", "mode_machine", "motor_cmd", "reserve", "crc"],
        MotorCmd_: ["mode", "q", "dq", "tau", "kp", "kd", "reserve"],
        MotorState_: [
            "mode",
            "q",
            "dq",
            "ddq",
            "tau_est",
            "temperature",
            "vol",
            "sensor",
            "motorstate",
            "reserve",
        ],
        IMUState_: ["quaternion", "gyroscope", "accelerometer", "rpy", "temperature"],
        LowState_: [
            "version",
            "mode_pr",
            "mode_machine",
            "tick",
            "imu_state",
            "motor_state",
            "wireless_remote",
            "reserve",
            "crc",
        ],
    }
    for cls, fields in expected.items():
        assert cls.__idl_typename__ == f"unitree_hg.msg.dds_.{cls.__name__}"
        assert list(cls.__annotations__) == fields
        assert cls.__idl_annotations__["extensibility"] == "final"
    assert Request_.__idl_typename__ == "unitree_api.msg.dds_.Request_"
    assert Response_.__idl_typename__ == "unitree_api.msg.dds_.Response_"
