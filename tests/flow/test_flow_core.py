"""The compiled core and the Python reference agree with waves on (1e-12 relative), and a
flow the core cannot represent runs on the reference, saying so."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from conftest import assert_rel, random_configuration

import uvms_pin as up
from uvms_pin.errors import CoreFallbackWarning
from uvms_pin.flow import AiryWave, GaussMarkovCurrent, IrregularSea, UniformCurrent
from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.compiled.extension import core_module
from uvms_pin.physics.compiled.flow import flow_to_core
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

ROOT = Path(__file__).resolve().parents[2]
FLOWS = {
    "deep sea + current": IrregularSea(0.8, 5.0, n_components=40, seed=2)
    + UniformCurrent([0.2, -0.1, 0.05]),
    "finite-depth wave": AiryWave(0.4, 4.0, heading_rad=0.5, water_depth_m=6.0, phase_rad=0.3),
}


@pytest.mark.parametrize("name", FLOWS)
def test_core_matches_the_reference_in_waves(reference_uvms, name):
    flow = FLOWS[name]
    rng = np.random.default_rng(5)
    uvms = reference_uvms
    for _ in range(5):
        q = random_configuration(uvms, rng)
        q[2] -= 3.0  # under water
        v = rng.normal(size=uvms.nv)
        tau = rng.normal(size=uvms.nv)
        tau_ext = rng.normal(size=uvms.nv)
        t = float(rng.uniform(0.0, 20.0))
        kw = {"flow": flow, "time_s": t}
        assert_rel(
            up.bias_forces(uvms, q, v, **kw), up.bias_forces(uvms, q, v, **kw, backend="python")
        )
        assert_rel(
            up.forward_dynamics(uvms, q, v, tau, tau_ext=tau_ext, **kw),
            up.forward_dynamics(uvms, q, v, tau, tau_ext=tau_ext, **kw, backend="python"),
        )
        # the waves do act
        assert not np.allclose(up.bias_forces(uvms, q, v, **kw), up.bias_forces(uvms, q, v))


def test_the_sea_state_closed_loop_is_the_same_on_both_backends():
    """0.4 s of the shipped sea-state scenario: the compiled plant (waves inside the one-call
    control period) and the Python reference give the same trajectory to 1e-9."""
    path = ROOT / "scenarios" / "sea_state_force_tracking.toml"
    runs = {
        backend: simulate(
            load_scenario(path, {"scenario.duration_s": 0.4, "integrator.backend": backend}),
            progress=False,
        )
        for backend in ("core", "python")
    }
    core, python = runs["core"], runs["python"]
    np.testing.assert_allclose(core.q, python.q, rtol=0, atol=1e-9)
    np.testing.assert_allclose(core.v, python.v, rtol=0, atol=1e-9)


def test_a_flow_the_core_cannot_represent_runs_on_the_reference(reference_uvms):
    gm = GaussMarkovCurrent([0.2, 0, 0], 0.05, 10.0, 0.1, seed=3)
    core = core_module()
    assert isinstance(flow_to_core(gm, core), Fallback)
    mixed_depths = AiryWave(0.1, 3.0, water_depth_m=5.0) + AiryWave(0.1, 4.0)
    assert isinstance(flow_to_core(mixed_depths, core), Fallback)
    assert flow_to_core(None, core).waves == []
    q = reference_uvms.neutral_configuration()
    q[2] = -2.0
    v = np.full(reference_uvms.nv, 0.1)
    with pytest.warns(CoreFallbackWarning, match="GaussMarkovCurrent"):
        h = up.bias_forces(reference_uvms, q, v, flow=gm, time_s=1.0)
    np.testing.assert_array_equal(
        h, up.bias_forces(reference_uvms, q, v, flow=gm, time_s=1.0, backend="python")
    )
    assert math.isinf(flow_to_core(IrregularSea(0.5, 5.0), core).water_depth_m)
