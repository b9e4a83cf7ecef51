"""Reading an MCAP in the order it was written (the official reader, unsorted), to check that every
channel's log time only goes forward: the recording's one monotonic time base."""

from __future__ import annotations

import json
from collections import defaultdict
from pathlib import Path

import numpy as np
from mcap.reader import make_reader


def written(path: Path) -> dict[str, list[tuple[int, dict]]]:
    """topic -> [(log_time ns, payload)] in file order."""
    by_topic: dict[str, list[tuple[int, dict]]] = defaultdict(list)
    with open(path, "rb") as f:
        for _, channel, message in make_reader(f).iter_messages(log_time_order=False):
            by_topic[channel.topic].append((message.log_time, json.loads(message.data)))
    return by_topic


def assert_never_back(path: Path) -> dict[str, list[tuple[int, dict]]]:
    rows = written(path)
    assert rows
    for topic, messages in rows.items():
        stamps = np.array([stamp for stamp, _ in messages], dtype=np.int64)
        assert np.all(np.diff(stamps) >= 0), f"{topic}: log time goes back {int(np.diff(stamps).min())} ns"
    return rows
