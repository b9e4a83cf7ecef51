"""A fake G1 on DDS for tests and benchmarks, run as its own process:

    python -m emopose.testing.fake_robot [--domain-id N] [--duration S] [--log FILE.jsonl]

Publishes rt/lowstate (500 Hz, valid CRC); takes rt/arm_sdk, ignores (and counts) commands with a
bad CRC, and moves each commanded arm joint toward  w * q_cmd + (1 - w) * q_firmware  with a
first-order lag (tau 0.05 s), w = motor_cmd[29].q (w = 0: the firmware holds its own pose).
Answers the loco RPCs (see fake_loco.py) and the voice RPCs, and streams a WAV as its microphone
(see fake_voice.py). --log writes one JSON line per received arm command
(q, weight, modes, gains, crc_ok; t when taken, sent_ns when the sender wrote it: the
batch-free send time), per loco request, and a final summary. Prints READY when up. SIGUSR1 stops
rt/lowstate for good (the arms' state lost, the loco and voice services still answering).
"""

from __future__ import annotations

import argparse
import json
import math
import signal
import sys
import threading
import time

import numpy as np

import emopose.backends.g1.wire as wire
from emopose.backends.g1.arm_command import decode_arm_command
from emopose.backends.g1.constants import LOCO_SERVICE, TOPIC_ARM_SDK, TOPIC_LOWSTATE
from emopose.backends.g1.dds import DdsSession, queue_qos
from emopose.backends.g1.hg_types import LowCmd_, LowState_
from emopose.execution.worker import Worker
from emopose.robot.g1_spec import NUM_MOTORS, WEIGHT_MOTOR
from emopose.testing.fake_loco import FakeLoco
from emopose.testing.fake_voice import FakeVoice, add_voice_args

DEFAULT_ARM_POSE = [0.3, 0.25, 0.0, 0.9, 0.0, 0.1, 0.0, 0.3, -0.25, 0.0, 0.9, 0.0, 0.1, 0.0]
_SDK_MOTORS = slice(12, 29)  # waist + arms: what arm_sdk may command


def quaternion_of(rpy: list[float]) -> tuple[float, float, float, float]:
    """(w, x, y, z) of roll, pitch, yaw applied as Rz(yaw) Ry(pitch) Rx(roll)."""
    cr, sr, cp, sp, cy, sy = (f(a / 2) for a in rpy for f in (math.cos, math.sin))
    return (cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy)


def floats(count: int):
    """argparse type: `count` comma-separated numbers."""
    def parse(text: str) -> list[float]:
        values = [float(v) for v in text.split(",")]
        if len(values) != count:
            raise argparse.ArgumentTypeError(f"needs {count} comma-separated values")
        return values
    return parse


class FakeG1:
    def __init__(self, args: argparse.Namespace) -> None:
        self.args = args
        # Line-buffered and kept open for the process's life; close() closes it.
        self._log_file = open(args.log, "a", buffering=1) if args.log else None  # noqa: SIM115
        self._log_lock = threading.Lock()
        self.session = DdsSession(args.domain_id, args.network_interface)
        self._state_writer = self.session.writer(TOPIC_LOWSTATE, LowState_)
        # When logging (tests), a deep reliable queue so the log holds every command even on a
        # loaded machine; otherwise the default QoS, as a robot would subscribe.
        self._cmd_reader = self.session.reader(
            TOPIC_ARM_SDK, LowCmd_, queue_qos(256) if args.log else None
        )
        forced = dict(tuple(int(v) for v in spec.split(":")) for spec in args.fail_api)
        self.loco = FakeLoco(self.session, args.loco_service, self.log, forced)
        self.voice = FakeVoice(self.session, args, self.log, forced)
        self.firmware_q = np.zeros(NUM_MOTORS)
        self.firmware_q[15:29] = args.arm_pose
        self.firmware_q[12:15] = args.waist
        self.q = self.firmware_q.copy()
        self._cmd_q = self.q.copy()
        self._cmd_mode = np.zeros(NUM_MOTORS, dtype=bool)
        self._weight = 0.0
        self._cmd_lock = threading.Lock()
        self.good = self.bad_crc = self.undecodable = 0
        self.lowstate_on = True
        self._stop = threading.Event()
        self._commands = Worker("fake-arm-sdk", self._take_commands, join_timeout_s=1.0)
        self._record = wire.new_lowstate()
        self._record["version"] = (1, 0)
        self._record["imu_state"]["quaternion"] = quaternion_of(args.imu_rpy)
        self._record["imu_state"]["rpy"] = args.imu_rpy
        self._record["imu_state"]["accelerometer"] = (0.0, 0.0, 9.81)

    def log(self, entry: dict) -> None:
        if self._log_file is not None:
            with self._log_lock:
                self._log_file.write(json.dumps(entry) + "\n")

    # -- rt/arm_sdk --------------------------------------------------------------------
    def _take_commands(self, stop: threading.Event) -> None:
        while not stop.is_set():
            try:
                samples = self._cmd_reader.take_stamped(timeout_s=0.05)
            except Exception:  # noqa: BLE001 - the session was closed under us: just stop
                return
            for data, sent_ns in samples:
                record = wire.lowcmd_from_cdr(data)
                if record is None:
                    self.undecodable += 1
                    continue
                ok = wire.crc_ok(record)
                if self._log_file is not None:
                    self.log({"kind": "arm", "t": time.monotonic(), "sent_ns": sent_ns,
                              **decode_arm_command(record)})
                if not ok:
                    self.bad_crc += 1  # the firmware drops it; so do we
                    continue
                self.good += 1
                motors = record["motor_cmd"]
                with self._cmd_lock:
                    self._cmd_mode[:] = False
                    self._cmd_mode[_SDK_MOTORS] = motors["mode"][_SDK_MOTORS] == 1
                    self._cmd_q[self._cmd_mode] = motors["q"][self._cmd_mode]
                    self._weight = float(np.clip(motors["q"][WEIGHT_MOTOR], 0.0, 1.0))

    # -- physics and rt/lowstate -------------------------------------------------------
    def _step(self, dt: float) -> None:
        with self._cmd_lock:
            target = self.firmware_q.copy()
            target[self._cmd_mode] = (
                self._weight * self._cmd_q[self._cmd_mode]
                + (1.0 - self._weight) * self.firmware_q[self._cmd_mode]
            )
        previous = self.q.copy()
        self.q += (1.0 - math.exp(-dt / self.args.tau)) * (target - self.q)
        motors = self._record["motor_state"]
        motors["q"] = self.q
        motors["dq"] = (self.q - previous) / dt if dt > 0 else 0.0
        self.loco.step(dt)

    def _publish_state(self, tick_ms: int) -> None:
        self._record["tick"] = tick_ms & 0xFFFFFFFF
        crc = wire.set_crc(self._record)
        if self.args.bad_lowstate_crc:
            self._record["crc"] = crc ^ 0x1
        self._state_writer.write(wire.lowstate_to_cdr(self._record))

    def run(self) -> None:
        self._commands.start()
        self.loco.start()
        self.voice.start()
        period = 1.0 / self.args.lowstate_hz
        start = last = time.monotonic()
        deadline = start
        self._publish_state(0)
        print("READY", flush=True)
        while not self._stop.is_set():
            deadline += period
            now = time.monotonic()
            if deadline > now:
                time.sleep(deadline - now)
            elif now - deadline > 0.1:
                deadline = now  # we were suspended: do not burst to catch up
            now = time.monotonic()
            self._step(now - last)
            last = now
            if self.args.duration and now - start >= self.args.duration:
                break
            if self.lowstate_on:
                self._publish_state(int((now - start) * 1000))

    def stop(self, *_: object) -> None:
        self._stop.set()

    def silence_lowstate(self, *_: object) -> None:
        self.lowstate_on = False
        self.log({"kind": "lowstate_silenced", "t": time.monotonic()})

    def close(self) -> None:
        self._stop.set()
        self._commands.stop()
        self.loco.stop()
        self.voice.stop()
        self.log(
            {
                "kind": "summary",
                "good": self.good,
                "bad_crc": self.bad_crc,
                "undecodable": self.undecodable,
                "odom": self.loco.odom,
                "fsm_id": self.loco.fsm_id,
                "arm_q": self.q[15:29].tolist(),
                **self.voice.summary(),
            }
        )
        self.session.close()
        if self._log_file is not None:
            self._log_file.close()


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        prog="python -m emopose.testing.fake_robot", description=__doc__.split("\n")[0]
    )
    p.add_argument("--domain-id", type=int, default=0)
    p.add_argument(
        "--network-interface", default=None, help="NIC name or IP (default: Cyclone's choice)"
    )
    p.add_argument("--duration", type=float, default=0.0, help="seconds to run (0: until SIGTERM/SIGINT)")
    p.add_argument("--log", default=None, help="JSONL file: every arm command, loco request, summary")
    p.add_argument("--lowstate-hz", type=float, default=500.0)
    p.add_argument("--tau", type=float, default=0.05, help="joint response time constant, s")
    p.add_argument(
        "--arm-pose",
        type=floats(14),
        default=DEFAULT_ARM_POSE,
        help="14 comma-separated joint angles the firmware holds (library order)",
    )
    p.add_argument("--waist", type=floats(3), default=[0.0, 0.0, 0.0],
                   help="waist yaw,roll,pitch the firmware holds (rad)")
    p.add_argument("--imu-rpy", type=floats(3), default=[0.0, 0.0, 0.0],
                   help="the pelvis IMU's roll,pitch,yaw (rad)")
    p.add_argument(
        "--bad-lowstate-crc", action="store_true", help="publish lowstate with a wrong CRC"
    )
    p.add_argument("--loco-service", default=LOCO_SERVICE)
    p.add_argument(
        "--fail-api",
        action="append",
        default=[],
        metavar="API:CODE",
        help="answer this loco or voice api id with this non-zero status (repeatable)",
    )
    add_voice_args(p)
    return p.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    robot = FakeG1(parse_args(argv))
    signal.signal(signal.SIGTERM, robot.stop)
    signal.signal(signal.SIGINT, robot.stop)
    signal.signal(signal.SIGUSR1, robot.silence_lowstate)
    try:
        robot.run()
    finally:
        robot.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
