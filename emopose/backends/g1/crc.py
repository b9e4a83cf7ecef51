"""The CRC that the G1 firmware checks on LowCmd_ (and sets on LowState_).

Rule (shared/reference/g1.md): pack the message as its little-endian C struct, read it as uint32
words, drop the last word (the crc itself), then feed each word MSB first into a CRC-32 register
(poly 0x04C11DB7, init 0xFFFFFFFF, no reflection, no final xor). That is CRC-32/MPEG-2 over the
words' big-endian bytes. Python's zlib only does the *reflected* CRC-32, so we run zlib over
bit-reversed bytes and bit-reverse the register back: the same CRC in C speed (~5 us for 1 kB)
instead of an 8000-step Python loop.
"""

from __future__ import annotations

import zlib

import numpy as np

POLY = 0x04C11DB7
_BITREV8 = bytes(int(f"{i:08b}"[::-1], 2) for i in range(256))


def _bitrev32(x: int) -> int:
    return int.from_bytes(x.to_bytes(4, "big").translate(_BITREV8), "little")


def crc32_words(packed: bytes | bytearray | memoryview | np.ndarray) -> int:
    """CRC over a packed struct: all its uint32 words except the last one (where the crc lives)."""
    words = np.frombuffer(packed, dtype="<u4")[:-1]
    msb_first = words.astype(">u4").tobytes()
    reflected = zlib.crc32(msb_first.translate(_BITREV8)) ^ 0xFFFFFFFF
    return _bitrev32(reflected)


def crc32_reference(packed: bytes) -> int:
    """The rule exactly as written in g1.md, bit by bit. Slow; for tests only."""
    n_words = len(packed) // 4 - 1
    words = np.frombuffer(packed, dtype="<u4")[:n_words]
    crc = 0xFFFFFFFF
    for w in words.tolist():
        for bit in range(31, -1, -1):
            top = crc & 0x80000000
            crc = (crc << 1) & 0xFFFFFFFF
            if top:
                crc ^= POLY
            if (w >> bit) & 1:
                crc ^= POLY
    return crc
