"""The G1 backend's shape: one state machine owns every transition, the supervisor sees a narrow
interface, importing the package runs no import cycle, and the fakes live outside the runtime."""

from __future__ import annotations

import ast
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from emopose.backends.g1 import G1BackendError
from emopose.backends.g1.lifecycle import ArmState, Lifecycle
from emopose.backends.g1.supervisor import Supervisor, Vitals, fault_reason
from emopose.clock import FakeClock

REPO = Path(__file__).resolve().parents[3]

# Records every import of a project module that is still executing: an import cycle.
CYCLE_PROBE = r"""
import builtins, sys
cycles = []
original = builtins.__import__
def probe(name, globals=None, locals=None, fromlist=(), level=0):
    module = sys.modules.get(name) if level == 0 else None
    spec = getattr(module, "__spec__", None)
    if name.startswith(("emopose.backends.g1", "emopose.testing")) and getattr(spec, "_initializing", False):
        cycles.append(f"{(globals or {}).get('__name__')} -> {name}")
    return original(name, globals, locals, fromlist, level)
builtins.__import__ = probe
import emopose.backends.g1 as g1
eager = sorted(m for m in sys.modules if m.startswith("emopose.backends.g1."))
import pkgutil, importlib
for package in ("emopose.backends.g1", "emopose.testing"):
    for info in pkgutil.iter_modules(importlib.import_module(package).__path__):
        importlib.import_module(f"{package}.{info.name}")
g1.G1Backend, g1.LocoClient, g1.G1BackendError
print(cycles)
print(eager)
"""


def test_importing_the_package_runs_no_cycle_and_loads_nothing_eagerly():
    pytest.importorskip("cyclonedds.domain", reason="the DDS modules need cyclonedds")
    done = subprocess.run([sys.executable, "-c", CYCLE_PROBE], cwd=REPO, capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    cycles, eager = done.stdout.strip().splitlines()[-2:]
    assert cycles == "[]"
    assert eager == "[]"  # backend, handover, cyclonedds: loaded when first used, not on import


def test_no_runtime_module_imports_the_fakes():
    runtime = [p for p in (REPO / "emopose").rglob("*.py") if "testing" not in p.parts]
    for path in runtime:
        for node in ast.walk(ast.parse(path.read_text())):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else \
                [node.module or ""] if isinstance(node, ast.ImportFrom) else []
            assert not any(n.startswith("emopose.testing") or "fake_" in n for n in names), path
    assert not (REPO / "emopose/backends/g1/fake_robot.py").exists()


def test_lifecycle_owns_every_transition():
    life = Lifecycle()
    with pytest.raises(G1BackendError, match="before connect"):
        life.stream()
    life.start_connect()
    with pytest.raises(G1BackendError, match="called twice"):
        life.start_connect()
    assert not life.claim_release()  # ramping: only an aborted connect may release
    life.connected()
    with life.lock:
        life.stream()
    assert life.state is ArmState.STREAMING == "streaming"
    assert life.claim_release(fault="deadman") and not life.claim_release()  # the first claim wins
    with pytest.raises(G1BackendError, match="deadman"):
        life.stream()
    life.released()
    life.closed()
    assert life.state is ArmState.FAILED and life.failure == "deadman"  # a fault stays a fault


class Stub:
    """A Supervised backend that is streaming and lets virtual time say how idle it is."""

    def __init__(self, clock: FakeClock) -> None:
        self.clock, self.last_send, self.faults = clock, 0.0, []
        self.failed = threading.Event()

    def vitals(self) -> Vitals:
        state = ArmState.RELEASING if self.faults else ArmState.STREAMING
        return Vitals(state, 0.0, self.clock.now() - self.last_send, "domain 0")

    def hold(self) -> None:
        raise AssertionError("a streaming backend is never held")

    def fail(self, reason: str) -> None:
        self.faults.append(reason)
        self.failed.set()


def test_supervisor_trips_the_deadman_through_the_narrow_interface():
    clock = FakeClock()
    stub = Stub(clock)
    supervisor = Supervisor(stub, clock, lowstate_loss_s=0.2, deadman_s=0.1)
    supervisor.start()
    clock.advance(0.09)
    assert not stub.failed.wait(0.05)
    clock.advance(0.02)
    assert stub.failed.wait(5.0)
    supervisor.stop()
    assert stub.faults == ["deadman: send() not called for 110 ms (limit 100 ms): the sequencer stalled"]


def test_fault_reasons():
    fine = Vitals(ArmState.HOLDING, 0.1, 10.0, "domain 3")  # holding: no deadman before the first send
    assert fault_reason(fine, 0.2, 0.1) is None
    lost = Vitals(ArmState.STREAMING, 0.25, 0.0, "domain 3")
    assert "no valid LowState_ for 250 ms (limit 200 ms, domain 3)" in fault_reason(lost, 0.2, 0.1)
