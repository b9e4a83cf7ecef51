"""G1 pieces that need no DDS: settings, command building, ramps, lifecycle errors."""

from __future__ import annotations

import numpy as np
import pytest

from emopose.backends.base import Backend
from emopose.backends.g1 import G1Backend, G1BackendError, profiles, wire
from emopose.backends.g1.arm_command import ArmCommandBuilder, decode_arm_command
from emopose.robot import g1_spec

DT = g1_spec.CONTROL_DT


def test_backend_satisfies_protocol_and_defaults():
    backend = G1Backend()
    assert isinstance(backend, Backend) and backend.name == "g1"
    s = backend.settings
    assert (s.domain_id, s.network_interface, s.lowstate_timeout_s) == (0, None, 2.0)
    assert s.lowstate_loss_s == pytest.approx(0.2) and s.deadman_s == pytest.approx(0.1)
    assert np.all(s.kp == 60.0) and np.all(s.kd == 1.5)
    assert (s.weight_ramp_up_s, s.weight_ramp_down_s, s.command_waist) == (1.0, 3.0, False)
    assert np.array_equal(s.lower, g1_spec.LOWER) and np.array_equal(s.upper, g1_spec.UPPER)


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"lower": [0.0] * 13}, "lower"),
        ({"kp": [60.0] * 3}, "kp"),
        ({"neutral_pose": [5.0] * 14}, "neutral_pose"),
        ({"lower": [1.0] * 14, "upper": [0.0] * 14}, "lower must be < upper"),
        ({"deadman_ms": 0}, "deadman_ms"),
        ({"domain_id": 400}, "domain_id"),
        ({"kd": [float("nan")] * 14}, "kd"),
    ],
)
def test_settings_errors_name_the_field(kwargs, field):
    with pytest.raises(ValueError, match=field):
        G1Backend(**kwargs)


def test_lifecycle_without_connect():
    backend = G1Backend()
    assert backend.measured() is None and not backend.is_connected
    with pytest.raises(G1BackendError, match="before connect"):
        backend.send(0.0, np.zeros(14))
    backend.close()
    backend.close()
    with pytest.raises(G1BackendError):
        backend.send(0.0, np.zeros(14))


def test_send_rejects_bad_targets_before_anything_else():
    backend = G1Backend()
    with pytest.raises(ValueError, match="14 finite"):
        backend.send(0.0, np.zeros(13))
    with pytest.raises(ValueError, match="14 finite"):
        backend.send(0.0, np.full(14, np.nan))


def test_builder_touches_only_arms_and_weight():
    kp = np.linspace(40, 60, 14)
    builder = ArmCommandBuilder(kp, np.full(14, 1.5))
    q = np.linspace(-0.5, 0.5, 14)
    cdr, crc = builder.build(q, 0.7)
    info = decode_arm_command(wire.lowcmd_from_cdr(cdr))
    assert info["crc_ok"] and info["others_zero"]
    assert np.allclose(info["q"], q, atol=1e-7) and info["weight"] == pytest.approx(0.7)
    assert (
        info["mode"] == [1] * 14 and np.allclose(info["kp"], kp) and info["waist_mode"] == [0, 0, 0]
    )
    record = wire.lowcmd_from_cdr(cdr)
    assert np.all(record["motor_cmd"]["dq"] == 0) and np.all(record["motor_cmd"]["tau"] == 0)
    assert int(record["crc"]) == crc


def test_builder_clips_weight_and_commands_waist_only_when_asked():
    builder = ArmCommandBuilder(
        np.full(14, 60.0), np.full(14, 1.5), np.array([0.1, -0.1, 0.05]), 50.0, 2.0
    )
    cdr, _ = builder.build(np.zeros(14), 1.7)
    info = decode_arm_command(wire.lowcmd_from_cdr(cdr))
    assert info["weight"] == 1.0 and info["waist_mode"] == [1, 1, 1]
    assert np.allclose(info["waist_q"], [0.1, -0.1, 0.05]) and info["others_zero"]


@pytest.mark.parametrize("duration", [0.3, 1.0, 3.0])
def test_weight_ramp_monotone_bounded_smooth(duration):
    up = profiles.ramp(0.0, 1.0, duration, DT)
    assert len(up) == round(duration / DT) and up[-1] == 1.0
    steps = np.diff(np.concatenate([[0.0], up]))
    assert np.all(steps >= 0) and np.all((up >= 0) & (up <= 1))
    assert steps.max() <= profiles.max_step(duration, DT) + 1e-12
    assert steps[0] < steps.max() / 5  # eases in: no jump at the start


@pytest.mark.parametrize("setting, refused", [("virtual", "real robot"), ("fake", "is not a clock")])
def test_the_g1_refuses_virtual_time_and_unknown_clocks(compose, tmp_path, setting, refused):
    """Issue 30 item 3 (fixed in emopose/clock.py): run.clock=virtual, or anything outside the closed set,
    never drives a real robot at CPU speed; building the run refuses it before anything connects."""
    from emopose.build import ConfigError, build_run

    with pytest.raises(ConfigError, match=refused):
        build_run(compose("planner=keyword", "backend=g1", f"run.clock={setting}"), tmp_path)
