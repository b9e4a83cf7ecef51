"""The LowCmd_/LowState_ CRC: g1.md's test vectors, the fast path against the literal rule."""

from __future__ import annotations

import struct

import numpy as np

from emopose.backends.g1 import wire
from emopose.backends.g1.arm_command import ArmCommandBuilder
from emopose.backends.g1.crc import crc32_reference, crc32_words

LOWCMD_FMT = "<2B2x" + "B3x5fI" * 35 + "5I"
LOWSTATE_FMT = "<2I2B2xI" + "13fh2x" + "B3x4f2hf7I" * 35 + "40B5I"


def vector_two_values() -> list:
    values = [0, 0]
    for i in range(35):
        if 15 <= i <= 28:
            values += [1, 0.25, 0.0, 0.0, 60.0, 1.5, 0]
        elif i == 29:
            values += [0, 1.0, 0.0, 0.0, 0.0, 0.0, 0]
        else:
            values += [0, 0.0, 0.0, 0.0, 0.0, 0.0, 0]
    return values + [0] * 5


def test_struct_sizes_match_g1_md():
    assert struct.calcsize(LOWCMD_FMT) == 1004 == wire.LOW_CMD.itemsize
    assert struct.calcsize(LOWSTATE_FMT) == 2092 == wire.LOW_STATE.itemsize


def test_vector_all_zero():
    packed = bytes(1004)
    assert crc32_reference(packed) == 0xFE172F9F
    assert crc32_words(packed) == 0xFE172F9F
    assert wire.set_crc(wire.new_lowcmd()) == 0xFE172F9F


def test_vector_arm_command():
    packed = struct.pack(LOWCMD_FMT, *vector_two_values())
    assert crc32_reference(packed) == 0xE3B255EC
    assert crc32_words(packed) == 0xE3B255EC
    _, crc = ArmCommandBuilder(np.full(14, 60.0), np.full(14, 1.5)).build(np.full(14, 0.25), 1.0)
    assert crc == 0xE3B255EC


def test_numpy_layout_packs_like_the_c_struct():
    rng = np.random.default_rng(1)
    values = [int(rng.integers(256)), int(rng.integers(256))]
    for _ in range(35):
        values += [
            int(rng.integers(256)),
            *rng.normal(size=5).astype(np.float32).tolist(),
            int(rng.integers(2**32)),
        ]
    values += rng.integers(2**32, size=5).tolist()
    packed = struct.pack(LOWCMD_FMT, *values)
    record = np.frombuffer(packed, dtype=wire.LOW_CMD).reshape(())
    assert record.tobytes() == packed
    assert record["motor_cmd"]["q"][3] == np.float32(values[2 + 3 * 7 + 1])


def test_fast_crc_equals_reference_on_random_messages():
    rng = np.random.default_rng(2)
    for size in (1004, 2092):
        for _ in range(3):
            packed = rng.integers(0, 256, size=size, dtype=np.uint8).tobytes()
            assert crc32_words(packed) == crc32_reference(packed)


def test_lowstate_crc_round_trip_and_corruption():
    record = wire.new_lowstate()
    record["tick"] = 1234
    record["motor_state"]["q"][15:29] = np.linspace(-1, 1, 14)
    crc = wire.set_crc(record)
    assert crc == crc32_reference(record.tobytes())
    assert wire.crc_ok(record)
    record["motor_state"]["q"][20] += 1e-3
    assert not wire.crc_ok(record)
