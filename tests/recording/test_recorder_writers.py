"""Writers never wait for the disk: the control loop's messages are queued while a chunk is compressed and
written; a stop arriving while the Recorder starts leaves a whole file."""

from __future__ import annotations

import threading

import pytest
from mcap.reader import make_reader

from emopose.clock import FakeClock
from emopose.recording import Recorder, read_recording


def test_a_write_does_not_wait_for_a_flush_in_progress(tmp_path):
    recorder = Recorder(tmp_path / "r.mcap", clock=FakeClock(), describe_robot=False)
    with recorder._io:  # as while the flusher compresses and fsyncs a chunk
        writer = threading.Thread(target=lambda: [recorder.write("/joints/command", k, {"k": k})
                                                  for k in range(100)])
        writer.start()
        writer.join(timeout=10.0)
        assert not writer.is_alive(), "a write waited for the MCAP writer"
    recorder.close()
    assert [m["k"] for _, m in read_recording(tmp_path / "r.mcap")["/joints/command"]] == list(range(100))


def test_a_stop_while_the_recorder_starts_leaves_a_readable_file(tmp_path, monkeypatch):
    def stopped():
        raise KeyboardInterrupt  # what a SIGTERM handler raises while the URDF is being built

    monkeypatch.setattr("emopose.robot.urdf.robot_urdf", stopped)
    with pytest.raises(KeyboardInterrupt):
        Recorder(tmp_path / "r.mcap", clock=FakeClock())
    with (tmp_path / "r.mcap").open("rb") as f:
        reader = make_reader(f)
        assert list(reader.iter_messages()) == []
        assert [m.name for m in reader.iter_metadata()] == ["emopose"]
