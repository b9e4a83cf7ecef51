"""Packed C layouts of LowCmd_/LowState_ as numpy records, and their CDR bytes on the wire.

Why not the cyclonedds serializer: in 0.10.2 it is pure Python and costs ~0.5 ms per LowCmd_
and ~0.7 ms per LowState_ (500 Hz!), and the CRC needs the C layout anyway. So the backend and
the fake robot keep each message as one numpy record in the C layout (what the CRC is defined
on, '<2B2x' + 'B3x5fI'*35 + '5I' for LowCmd_), fill it with vectorised assignments, and convert
to/from XCDR with a few byte slices. tests/backends/g1/test_wire.py checks these bytes against
the cyclonedds serializer for random messages, in both directions.

CDR vs C: CDR aligns each member relative to the payload start but, unlike C, does not align a
nested struct's *start* to its widest member. The only differences are therefore right before
motor 0, whose leading uint8 `mode` sits 2 bytes earlier in LowCmd_ and in LowState_ in CDR:
    LowCmd_   C[0:2] pad[2:4] m0.mode[4] pad[5:8] rest[8:]   -> CDR C[0:2] C[4] 0 C[8:]
    LowState_ C[0:70] pad[70:72] m0.mode[72] pad[73:76] rest[76:] -> CDR C[0:70] C[72] 0 C[76:]
"""

from __future__ import annotations

import numpy as np

from emopose.backends.g1.crc import crc32_words
from emopose.robot.g1_spec import NUM_MOTORS

# 4-byte encapsulation header: CDR little-endian (XCDR1). Final structs without 8-byte members
# have the same body under XCDR2 (header 0x0007), which we also accept when decoding.
CDR_LE_HEADER = b"\x00\x01\x00\x00"
_ACCEPTED_HEADERS = (b"\x00\x01", b"\x00\x07")


def _struct(fields: list[tuple[str, object, int]], itemsize: int) -> np.dtype:
    names, formats, offsets = zip(*fields)
    return np.dtype({"names": names, "formats": formats, "offsets": offsets, "itemsize": itemsize})


MOTOR_CMD = _struct(
    [
        ("mode", "u1", 0),
        ("q", "<f4", 4),
        ("dq", "<f4", 8),
        ("tau", "<f4", 12),
        ("kp", "<f4", 16),
        ("kd", "<f4", 20),
        ("reserve", "<u4", 24),
    ],
    28,
)
LOW_CMD = _struct(
    [
        ("mode_pr", "u1", 0),
        ("mode_machine", "u1", 1),
        ("motor_cmd", (MOTOR_CMD, NUM_MOTORS), 4),
        ("reserve", ("<u4", 4), 984),
        ("crc", "<u4", 1000),
    ],
    1004,
)
IMU_STATE = _struct(
    [
        ("quaternion", ("<f4", 4), 0),
        ("gyroscope", ("<f4", 3), 16),
        ("accelerometer", ("<f4", 3), 28),
        ("rpy", ("<f4", 3), 40),
        ("temperature", "<i2", 52),
    ],
    56,
)
MOTOR_STATE = _struct(
    [
        ("mode", "u1", 0),
        ("q", "<f4", 4),
        ("dq", "<f4", 8),
        ("ddq", "<f4", 12),
        ("tau_est", "<f4", 16),
        ("temperature", ("<i2", 2), 20),
        ("vol", "<f4", 24),
        ("sensor", ("<u4", 2), 28),
        ("motorstate", "<u4", 36),
        ("reserve", ("<u4", 4), 40),
    ],
    56,
)
LOW_STATE = _struct(
    [
        ("version", ("<u4", 2), 0),
        ("mode_pr", "u1", 8),
        ("mode_machine", "u1", 9),
        ("tick", "<u4", 12),
        ("imu_state", IMU_STATE, 16),
        ("motor_state", (MOTOR_STATE, NUM_MOTORS), 72),
        ("wireless_remote", ("u1", 40), 2032),
        ("reserve", ("<u4", 4), 2072),
        ("crc", "<u4", 2088),
    ],
    2092,
)
assert LOW_CMD.itemsize == 1004 and LOW_STATE.itemsize == 2092  # sizes given in g1.md

_CMD_CUT = 2  # bytes before motor 0 in the C layout that precede the padding
_STATE_CUT = 70


def _field_mask(dtype: np.dtype) -> np.ndarray:
    """0xFF over every byte of a field, 0 over padding (nested structs and arrays too)."""
    mask = np.zeros(dtype.itemsize, dtype=np.uint8)
    if dtype.fields is None:
        mask[:] = 0xFF
        return mask
    for sub, offset in (dtype.fields[name][:2] for name in dtype.names):
        base, shape = (sub.base, sub.shape) if sub.subdtype else (sub, ())
        inner = _field_mask(base)
        for k in range(int(np.prod(shape, dtype=int))):
            start = offset + k * base.itemsize
            mask[start : start + base.itemsize] = inner
    return mask


# Padding is zeroed on decode so the CRC sees the C struct a value-initialised sender would have
# (the cyclonedds Python serializer does not promise zero padding bytes).
_CMD_MASK = _field_mask(LOW_CMD)
_STATE_MASK = _field_mask(LOW_STATE)


def new_lowcmd() -> np.ndarray:
    """A zeroed LowCmd_ record (shape (), C layout, padding zero as the CRC expects)."""
    return np.zeros((), dtype=LOW_CMD)


def new_lowstate() -> np.ndarray:
    return np.zeros((), dtype=LOW_STATE)


def set_crc(record: np.ndarray) -> int:
    """Compute the CRC over the record's C bytes and store it in record['crc']."""
    crc = crc32_words(record.tobytes())
    record["crc"] = crc
    return crc


def crc_ok(record: np.ndarray) -> bool:
    return int(record["crc"]) == crc32_words(record.tobytes())


def _c_to_cdr(c: bytes, cut: int) -> bytes:
    return b"".join((CDR_LE_HEADER, c[:cut], c[cut + 2 : cut + 3], b"\x00", c[cut + 6 :]))


def _cdr_to_c(data: bytes, cut: int, dtype: np.dtype, mask: np.ndarray) -> np.ndarray | None:
    """A writable 0-d record in C layout, or None unless `data` is little-endian CDR this long."""
    if data[:2] not in _ACCEPTED_HEADERS or len(data) < dtype.itemsize:
        return None  # big-endian, another representation, or truncated
    body = data[4:]
    c = b"".join((body[:cut], b"\x00\x00", body[cut : cut + 1], b"\x00\x00\x00", body[cut + 2 :]))
    raw = np.frombuffer(c, dtype=np.uint8, count=dtype.itemsize) & mask
    return raw.view(dtype).reshape(())


def lowcmd_to_cdr(record: np.ndarray) -> bytes:
    return _c_to_cdr(record.tobytes(), _CMD_CUT)


def lowstate_to_cdr(record: np.ndarray) -> bytes:
    return _c_to_cdr(record.tobytes(), _STATE_CUT)


def lowcmd_from_cdr(data: bytes) -> np.ndarray | None:
    return _cdr_to_c(data, _CMD_CUT, LOW_CMD, _CMD_MASK)


def lowstate_from_cdr(data: bytes) -> np.ndarray | None:
    return _cdr_to_c(data, _STATE_CUT, LOW_STATE, _STATE_MASK)
