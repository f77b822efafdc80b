"""The compiled core: loading, backends, errors, fallbacks; the closed loop against Python."""

from __future__ import annotations

import pickle
import warnings

import numpy as np
import pytest
from conftest import ROOT

import uvms_pin as up
from uvms_pin.errors import CoreFallbackWarning, ParameterError, SimulationError
from uvms_pin.physics.compiled import extension as core
from uvms_pin.physics.disturbance import SinusoidalDisturbance
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System

SCENARIO = ROOT / "scenarios" / "realistic_force_tracking.toml"


def test_the_core_is_built_from_these_sources_against_this_pinocchio():
    import pinocchio as pin

    module = core.core_module()
    assert module.SOURCE_HASH == core.source_hash()
    assert module.PINOCCHIO_VERSION == pin.__version__


def test_stale_core_says_how_to_rebuild(monkeypatch):
    monkeypatch.setattr(core, "source_hash", lambda: "0" * 64)
    monkeypatch.setattr(core, "_MODULE", [])
    with pytest.raises(core.CoreUnavailableError, match=r"stale.*pip install -e"):
        core.core_module()


def test_missing_core_says_how_to_rebuild(monkeypatch):
    import builtins

    real_import = builtins.__import__

    def no_core(name, globals=None, locals=None, fromlist=(), level=0):
        if fromlist and "_core" in fromlist:
            raise ImportError("No module named 'uvms_pin._core'")
        return real_import(name, globals, locals, fromlist, level)

    monkeypatch.setattr(builtins, "__import__", no_core)
    monkeypatch.setattr(core, "_MODULE", [])
    with pytest.raises(core.CoreUnavailableError, match=r"not built.*pip install -e"):
        core.core_module()


def test_bad_input_raises_parameter_errors(reference_uvms):
    uvms = reference_uvms
    q, v = uvms.neutral_configuration(), np.zeros(uvms.nv)
    with pytest.raises(ParameterError, match=r"q must have shape \(11,\), got \(3,\)"):
        up.forward_dynamics(uvms, np.zeros(3), v, v)
    with pytest.raises(ParameterError, match="v contains a non-finite value"):
        up.bias_forces(uvms, q, np.full(uvms.nv, np.nan))
    with pytest.raises(ParameterError, match="tau"):
        up.forward_dynamics(uvms, q, v, np.zeros((2, 5)))
    with pytest.raises(ParameterError, match="backend"):
        up.mass_matrix(uvms, q, backend="fortran")
    with pytest.raises(ParameterError, match="backend"):
        Plant(uvms, backend="gpu")
    # lists are accepted like arrays
    np.testing.assert_array_equal(up.mass_matrix(uvms, list(q)), up.mass_matrix(uvms, q))


def test_singular_mass_matrix_raises_simulation_error(reference_uvms):
    import pinocchio as pin

    model = pin.Model(reference_uvms.model)
    for j in range(1, model.njoints):
        model.inertias[j] = pin.Inertia.Zero()
    massless = reference_uvms.with_hydro(lambda b: up.HydroParams.dry()).with_model(model)
    with pytest.raises(SimulationError, match="positive definite"):
        up.forward_dynamics(massless, massless.neutral_configuration(), np.zeros(10), np.zeros(10))


def test_python_disturbance_falls_back_and_says_so(reference_uvms):
    def gust(t: float) -> np.ndarray:
        return np.array([0.1 * t, 0.0, 0.0, 0.0, 0.0, 0.0])

    q0, v0 = reference_uvms.neutral_configuration(), np.zeros(reference_uvms.nv)
    tau = np.zeros(reference_uvms.nv)
    plant = Plant(reference_uvms, disturbance=gust)
    reference = Plant(reference_uvms, disturbance=gust, backend="python")
    with pytest.warns(CoreFallbackWarning, match="disturbance"):
        q, v = System(plant).advance(RK4(5e-4), 0.0, q0, v0, tau, 0.002)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # said once per plant
        q, v = System(plant).advance(RK4(5e-4), 0.002, q, v, tau, 0.004)
    q_ref, v_ref = System(reference).advance(RK4(5e-4), 0.0, q0, v0, tau, 0.002)
    q_ref, v_ref = System(reference).advance(RK4(5e-4), 0.002, q_ref, v_ref, tau, 0.004)
    np.testing.assert_allclose(v, v_ref, rtol=1e-12, atol=1e-15)
    assert v[0] != 0.0  # the gust pushed


def test_plant_and_uvms_pickle_after_core_use(reference_uvms):
    uvms = reference_uvms.copy()
    plant = Plant(uvms, disturbance=SinusoidalDisturbance())
    q, v = uvms.neutral_configuration(), np.zeros(uvms.nv)
    a = plant.acceleration(0.3, q, v, np.zeros(uvms.nv))
    clone = pickle.loads(pickle.dumps(plant))
    np.testing.assert_array_equal(clone.acceleration(0.3, q, v, np.zeros(uvms.nv)), a)


def test_realistic_closed_loop_matches_the_python_reference_over_2_s():
    overrides = {"scenario.duration_s": 2.0}
    rollouts = {}
    for backend in ("core", "python"):
        scenario = up.load_scenario(SCENARIO, {**overrides, "integrator.backend": backend})
        assert scenario.plant.backend == backend
        rollouts[backend] = up.simulate(scenario)
    fast, slow = rollouts["core"], rollouts["python"]
    assert fast.metadata["status"] == slow.metadata["status"] == "ok"
    assert len(fast) == len(slow) == 201
    for name in ("q", "v", "tau"):
        a, b = getattr(fast, name), getattr(slow, name)
        scale = np.max(np.abs(b), axis=0) + 1.0
        assert np.max(np.abs(a - b) / scale) < 1e-9, name
