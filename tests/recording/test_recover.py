"""A torn recording (its writer killed) is rewritten into one the official reader accepts, losing only
the chunk in progress: python -m emopose.recover FILE [OUT]."""

from __future__ import annotations

import subprocess
import sys

import pytest
from mcap.exceptions import McapError
from mcap.reader import make_reader

from emopose.clock import FakeClock
from emopose.recording import Recorder
from emopose.recover import recover
from tests.recording.conftest import every_message


def _written(tmp_path):
    clock = FakeClock()
    recorder = Recorder(tmp_path / "full.mcap", clock=clock, describe_robot=False)
    for k in range(300):
        recorder.write_now("/note", {"k": k})
        clock.sleep_until(clock.now() + 0.01)
        if k % 50 == 49:
            recorder.flush()  # what the flusher thread does every FLUSH_S
    return recorder


def test_a_torn_file_is_rewritten_with_every_flushed_message(tmp_path):
    recorder = _written(tmp_path)
    torn = tmp_path / "torn.mcap"
    torn.write_bytes((tmp_path / "full.mcap").read_bytes())  # as a kill -9 leaves it: no footer
    recorder.close()
    with pytest.raises(McapError), torn.open("rb") as f:  # the official reader refuses it
        list(make_reader(f).iter_messages())
    done = recover(torn)
    assert not done.complete and done.out == tmp_path / "torn.recovered.mcap"
    assert [m["k"] for _, _, _, m in every_message(done.out)] == list(range(300))


def test_a_file_cut_mid_chunk_keeps_the_chunks_before(tmp_path):
    _written(tmp_path).close()
    data = (tmp_path / "full.mcap").read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: len(data) * 2 // 3])
    ks = [m["k"] for _, _, _, m in every_message(recover(cut).out)]
    assert ks == list(range(len(ks))) and len(ks) % 50 == 0 and 0 < len(ks) < 300


def test_the_command_line_says_one_line(tmp_path):
    _written(tmp_path)
    ok = subprocess.run(
        [sys.executable, "-m", "emopose.recover", str(tmp_path / "full.mcap"), str(tmp_path / "out.mcap")],
        capture_output=True,
        text=True,
    )
    assert ok.returncode == 0 and "recovered 300 messages on 1 channels" in ok.stdout
    bad = subprocess.run(
        [sys.executable, "-m", "emopose.recover", str(tmp_path / "none.mcap")], capture_output=True, text=True
    )
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and "does not exist" in bad.stderr
