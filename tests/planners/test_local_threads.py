"""torch's threads sized to the free cores (planners/local/threads.py)."""

from emopose.planners.local.threads import _cpu_times, busy_cores, free_threads, resolve_threads

STAT = ("cpu  10 0 10 80 0 0 0 0 0 0\n"
        "cpu0 100 0 0 100 0 0 0 0 0 0\n"
        "cpu1 0 0 0 200 0 0 0 0 0 0\n")


def test_a_busy_core_is_left_to_its_process():
    assert free_threads(2, 0.0) == 2
    assert free_threads(2, 0.2) == 2   # a core a third busy or less counts as free
    assert free_threads(2, 1.0) == 1
    assert free_threads(2, 2.0) == 1   # never fewer than one
    assert free_threads(16, 3.5) == 12


def test_cpu_times_read_only_the_usable_cores():
    assert _cpu_times(STAT, [0]) == (100.0, 200.0)
    assert _cpu_times(STAT, [0, 1]) == (100.0, 400.0)


def test_busy_cores_from_two_samples(tmp_path, monkeypatch):
    stat = tmp_path / "stat"
    samples = iter([STAT, STAT.replace("cpu0 100 0 0 100", "cpu0 200 0 0 100")])
    stat.write_text(next(samples))
    monkeypatch.setattr("emopose.planners.local.threads.time.sleep", lambda _: stat.write_text(next(samples)))
    assert busy_cores([0, 1], stat_path=str(stat)) == 2 * 100 / 100  # cpu0 ran every jiffy: one core


def test_a_configured_count_is_used_as_given():
    assert resolve_threads(3) == 3
