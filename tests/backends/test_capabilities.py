"""The Backend base class and the capability protocols: which backend (or part) declares what."""

from __future__ import annotations

import numpy as np
import pytest
from hydra.utils import instantiate

from emopose.backends.base import Backend
from emopose.backends.capabilities import FrameSource, PlanarBase, Renderable, SimulatedState
from emopose.backends.dry_run import DryRunBackend
from emopose.backends.g1 import G1Backend
from emopose.backends.mujoco import MujocoBackend
from emopose.backends.planar_base import MujocoPlanarBase
from emopose.backends.sim_renderer import SimRenderer

CAPABILITIES = (SimulatedState, Renderable, FrameSource, PlanarBase)


def declared(obj) -> set[type]:
    return {c for c in CAPABILITIES if isinstance(obj, c)}


def test_every_backend_is_a_backend_and_says_whether_it_needs_the_wall_clock():
    backends = {DryRunBackend(): False, MujocoBackend(): False, G1Backend(): True}
    for backend, realtime in backends.items():
        assert isinstance(backend, Backend) and backend.realtime is realtime, backend.name
    assert [b.name for b in backends] == ["dry_run", "mujoco", "g1"]


def test_capabilities_are_declared_only_where_they_exist():
    assert declared(DryRunBackend()) == set()
    assert declared(G1Backend()) == set()  # its base walks through the loco client, not the backend
    backend = MujocoBackend()
    assert declared(backend) == {SimulatedState, Renderable}
    assert declared(backend.renderer) == {Renderable, FrameSource}
    assert backend.planar_base is None
    assert declared(MujocoBackend(planar_base=MujocoPlanarBase()).planar_base) == {PlanarBase}


def test_a_backend_must_implement_the_whole_interface():
    class Partial(Backend):
        name = "partial"

        def connect(self, recorder):
            return None

    with pytest.raises(TypeError, match="abstract"):
        Partial()


def test_dry_run_echoes_what_it_was_sent():
    backend = DryRunBackend(initial_pose=[0.1] * 14)
    assert not backend.is_connected
    np.testing.assert_allclose(backend.connect(None), 0.1)
    assert backend.is_connected
    np.testing.assert_allclose(backend.send(0.0, np.full(14, 0.2)), 0.2)  # no limits: sent as asked
    np.testing.assert_allclose(backend.measured(), 0.2)
    assert backend.sent == 1
    backend.close()
    assert not backend.is_connected


def test_composed_mujoco_config_attaches_the_renderer_and_the_chosen_base(compose):
    plain = instantiate(compose("backend=mujoco", "backend.renderer.every=25").backend, _convert_="all")
    assert isinstance(plain, MujocoBackend) and plain.planar_base is None
    assert isinstance(plain.renderer, SimRenderer) and plain.renderer.every == 25
    base = "+backend.planar_base._target_=emopose.backends.planar_base.MujocoPlanarBase"
    toured = instantiate(compose("backend=mujoco", base).backend, _convert_="all")
    assert isinstance(toured.planar_base, PlanarBase) and isinstance(toured.renderer, SimRenderer)


@pytest.mark.parametrize("name, cls", [("dry_run", DryRunBackend), ("g1", G1Backend)])
def test_other_backend_configs_build_plain_backends(compose, name, cls):
    backend = instantiate(compose(f"backend={name}").backend, _convert_="all")
    assert type(backend) is cls and declared(backend) == set()
