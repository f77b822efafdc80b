"""A URDF loaded once per process (`loaded_uvms`): the copies are the model a fresh load gives,
independent, and a study run on a cached model gives the rollout of a fresh one, bit for bit."""

from __future__ import annotations

import dataclasses
import warnings
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import uvms_pin as up
from uvms_pin.apps.study.plant import modify_plant
from uvms_pin.errors import FunnelViolation
from uvms_pin.model.scaled import scaled_uvms
from uvms_pin.model.urdf.load import load_uvms
from uvms_pin.model.urdf.loaded import loaded_uvms
from uvms_pin.model.uvms import UVMS

ROOT = Path(__file__).resolve().parents[3]
SCENARIO = ROOT / "scenarios" / "realistic_force_tracking.toml"
MODEL = ROOT / "models" / "uvms_lbv150.urdf"
FACTORS = {"mass_scale": 1.3, "added_mass_scale": 0.6, "damping_scale": 1.4, "buoyancy_scale": 0.8}


def _same_model(a: UVMS, b: UVMS) -> None:
    assert a.model == b.model
    assert a.hydro_bodies == b.hydro_bodies
    for name in ("added_mass_per_joint", "volume_per_joint_m3", "center_of_buoyancy_per_joint_m",
                 "damping_linear", "damping_quadratic"):  # fmt: skip
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert (a.ee_frame_id, a.sensor_frame_id, a.source) == (
        b.ee_frame_id,
        b.sensor_frame_id,
        b.source,
    )


def test_a_cached_load_is_a_fresh_load_with_its_own_buffers():
    path = MODEL
    fresh = load_uvms(path, water_density_kg_m3=1000.0)
    first = loaded_uvms(path, water_density_kg_m3=1000.0)
    second = loaded_uvms(path, water_density_kg_m3=1000.0)
    _same_model(first, fresh)
    _same_model(second, fresh)
    assert second is not first and second.data is not first.data and second.cache is not first.cache
    other = loaded_uvms(path, water_density_kg_m3=1025.0)  # another density: another model
    assert other.water_density_kg_m3 == 1025.0 and not np.isclose(
        other.net_buoyancy_N, first.net_buoyancy_N
    )


def test_an_edited_file_is_loaded_again_and_its_warnings_are_given_every_time(tmp_path):
    source = MODEL
    text = source.read_text()
    path = tmp_path / "model.urdf"
    path.write_text(text)
    loaded_uvms(path, water_density_kg_m3=1025.0)
    # a heavier vehicle: mass edited, same path
    heavier = text.replace('<mass value="', '<mass value="1', 1)
    assert heavier != text
    path.write_text(heavier)
    with warnings.catch_warnings(record=True) as first:
        warnings.simplefilter("always")
        edited = loaded_uvms(path, water_density_kg_m3=1025.0)
    _same_model(edited, load_uvms(path, water_density_kg_m3=1025.0))
    with warnings.catch_warnings(record=True) as again:
        warnings.simplefilter("always")
        loaded_uvms(path, water_density_kg_m3=1025.0)  # from the cache
    assert [str(w.message) for w in again] == [str(w.message) for w in first]


def test_a_study_run_on_the_cached_model_is_the_run_on_a_fresh_one():
    """The scaled plant of a cached model (the sweep's path) against one scaled from a model
    loaded afresh: the same rollout, bit for bit."""
    overrides = {"scenario.duration_s": 0.3, "environment.stiffness_N_m": [20.0, 20.0, 20.0]}
    up.load_scenario(SCENARIO, overrides)  # the model in the cache
    cached = modify_plant(up.load_scenario(SCENARIO, overrides), FACTORS)
    fresh = up.load_scenario(SCENARIO, overrides)
    model = load_uvms(fresh.uvms.source, water_density_kg_m3=fresh.uvms.water_density_kg_m3)
    plant = dataclasses.replace(fresh.plant, uvms=model)
    fresh = modify_plant(dataclasses.replace(fresh, plant=plant), FACTORS)
    assert cached.uvms.model.inertias[1] == fresh.uvms.model.inertias[1]
    rollouts = []
    for scenario in (cached, fresh):
        try:
            rollouts.append(up.simulate(scenario, progress=False))
        except FunnelViolation as exc:
            rollouts.append(exc.rollout)
    a, b = rollouts
    assert len(a) > 10
    for name in ("time_s", "q", "v", "tau", "kinetic_energy_J", "potential_energy_J"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    np.testing.assert_array_equal(a.signals["wet_fraction"], b.signals["wet_fraction"])
    assert a.metrics().keys() == b.metrics().keys()


def test_a_rescaled_copy_has_its_own_inertias_and_the_original_keeps_its_own():
    uvms = loaded_uvms(MODEL, water_density_kg_m3=1025.0)
    q = uvms.neutral_configuration()
    before = up.mass_matrix(uvms, q)
    heavier = scaled_uvms(uvms, mass_scale=2.0)  # with_model: the hydrodynamics shared
    assert heavier.added_mass_per_joint is uvms.added_mass_per_joint
    assert not np.allclose(up.mass_matrix(heavier, q), before)
    np.testing.assert_array_equal(up.mass_matrix(uvms, q), before)
    _same_model(heavier.copy(), heavier)


@pytest.mark.parametrize("bad", ["missing.urdf"])
def test_a_missing_file_is_the_loaders_error(tmp_path, bad):
    with pytest.raises(up.ModelError):
        loaded_uvms(tmp_path / bad, water_density_kg_m3=1025.0)


@pytest.mark.parametrize("bad", [None, 3, ["a.urdf"]])
def test_a_path_that_is_not_one_is_a_parameter_error(bad):
    with pytest.raises(up.ParameterError, match="urdf_path must be a path"):
        up.load_uvms(bad)


def test_a_mass_scale_scales_the_whole_rigid_body_mass_matrix_armature_included():
    """M_rb (Pinocchio's CRBA: the bodies' inertias and the joints' armature) of a copy
    with mass_scale s is s M_rb, on a model whose arm joints have a rotor's armature."""
    uvms = loaded_uvms(MODEL, water_density_kg_m3=1025.0)
    model = pin.Model(uvms.model)
    model.armature[6:] = 0.02  # kg m^2 on each arm joint
    geared = uvms.with_model(model)
    q = uvms.neutral_configuration()
    q[7:] = np.linspace(0.2, 0.8, model.nq - 7)  # the arm bent: M_rb couples its joints
    heavier = scaled_uvms(geared, mass_scale=1.7)
    np.testing.assert_array_equal(heavier.model.armature, 1.7 * model.armature)
    m_rb = pin.crba(model, model.createData(), q)
    np.testing.assert_allclose(
        pin.crba(heavier.model, heavier.model.createData(), q), 1.7 * m_rb, rtol=1e-12, atol=1e-12
    )
