"""The tour's base is a config group (conf/tour/base/): each option opens its base or says what is missing."""

from __future__ import annotations

from types import SimpleNamespace

import pytest
from omegaconf import OmegaConf

from emopose.backends.dry_run import DryRunBackend
from emopose.backends.mujoco import MujocoBackend
from emopose.backends.planar_base import MujocoPlanarBase
from emopose.build import make
from emopose.tour.g1_base import G1TourBase
from emopose.tour.job import TourJob
from emopose.tour.scenario import TourConfigError
from emopose.tour.scenario_loading import load_tour
from emopose.tour.sim_base import MujocoBase, SimTourBase
from tests.tour.tour_helpers import LAB_FILE


def test_tour_lab_walks_on_the_simulated_base_and_g1_is_one_override(compose):
    cfg = compose("+experiment=tour_lab")
    assert cfg.job.base._target_ == "emopose.tour.sim_base.SimTourBase"
    assert isinstance(TourJob(base=OmegaConf.to_container(cfg.job.base)).tour_base(), SimTourBase)
    g1 = compose("+experiment=tour_lab", "backend=g1", "tour/base=g1", "backend.network_interface=lo")
    built = make(g1.job.base, "job.base")
    assert isinstance(built, G1TourBase)
    # The DDS domain and interface have one place: the backend's node.
    assert (built.domain_id, built.network_interface) == (g1.backend.domain_id, "lo")


def test_the_simulated_base_opens_at_the_start_and_refuses_a_backend_without_one():
    spec = load_tour(LAB_FILE)
    backend = MujocoBackend(planar_base=MujocoPlanarBase())
    backend.connect(None)
    try:
        base = SimTourBase().open(backend, spec)
        assert isinstance(base, MujocoBase) and base.odometry() == spec.start.pose()
    finally:
        backend.close()
    with pytest.raises(TourConfigError, match="backend=dry_run has none"):
        SimTourBase().open(DryRunBackend(), spec)


def test_the_g1_base_needs_an_odometry_factory_and_a_job_needs_a_base():
    with pytest.raises(TourConfigError, match="job.base.odometry"):
        G1TourBase(domain_id=0, network_interface=None).open(SimpleNamespace(name="g1"), load_tour(LAB_FILE))
    with pytest.raises(TourConfigError, match="tour/base"):
        TourJob().tour_base()
