"""How many threads torch gets for the local planner: the cores that are free when it starts.

PyTorch starts one thread per core. On a machine where another process keeps a core busy, the thread
placed on that core runs at half speed and every parallel operator waits for it, so a batch took 10 to
20 times longer instead of twice (issue 29: first-use training went from 3.5 to 14 minutes with one core
busy). Sizing the pool to the cores that are idle at the start keeps a busy core's cost near the share of
the machine it takes. "auto" samples /proc/stat over a short interval (the load average where there is
no /proc); a number is used as given.
"""

from __future__ import annotations

import logging
import os
import time
from contextlib import contextmanager
from pathlib import Path

log = logging.getLogger(__name__)
SAMPLE_S = 0.3


def usable_cores() -> list[int]:
    """The CPUs this process may run on."""
    try:
        return sorted(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return list(range(os.cpu_count() or 1))


def _cpu_times(stat: str, cores: list[int]) -> tuple[float, float]:
    """(busy, total) jiffies summed over the cores, from /proc/stat's text."""
    busy = total = 0.0
    wanted = {f"cpu{c}" for c in cores}
    for line in stat.splitlines():
        name, *fields = line.split()
        if name in wanted:
            values = [float(v) for v in fields[:8]]
            idle = values[3] + values[4]  # idle + iowait
            total += sum(values)
            busy += sum(values) - idle
    return busy, total


def busy_cores(cores: list[int], sample_s: float = SAMPLE_S, stat_path: str = "/proc/stat") -> float:
    """How many of the cores other work kept busy over the sample (the 1-minute load average without
    /proc/stat)."""
    path = Path(stat_path)
    if not path.is_file():
        return min(float(len(cores)), os.getloadavg()[0])
    busy0, total0 = _cpu_times(path.read_text(), cores)
    time.sleep(sample_s)
    busy1, total1 = _cpu_times(path.read_text(), cores)
    if total1 <= total0:
        return 0.0
    return len(cores) * (busy1 - busy0) / (total1 - total0)


def free_threads(cores: int, busy: float) -> int:
    """Threads for `cores` usable cores of which `busy` are taken: the idle ones, at least one (a core
    counts as taken when more than a third of it is)."""
    return max(1, cores - int(busy + 2 / 3))


def resolve_threads(setting: int | str) -> int:
    """planner.threads: a count as given, or "auto": the free cores right now."""
    if setting != "auto":
        return int(setting)
    cores = usable_cores()
    busy = busy_cores(cores)
    threads = free_threads(len(cores), busy)
    log.info("local planner: %d of %d cores free (%.1f busy): %d torch thread(s)",
             threads, len(cores), busy, threads)
    return threads


@contextmanager
def torch_threads(count: int):
    """torch's intra-op pool at `count` threads for the block, restored after."""
    import torch

    before = torch.get_num_threads()
    torch.set_num_threads(count)
    try:
        yield
    finally:
        torch.set_num_threads(before)
