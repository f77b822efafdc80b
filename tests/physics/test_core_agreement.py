"""The compiled core against the Python reference (its oracle): 1e-12 relative on random states.

Reference model, every shipped model file, three mounted example-robot-data arms and a
ball-jointed arm; with and without a current; with
external generalized forces, the spring and plane contacts and the sinusoidal disturbance; the
plant advanced over a control period by RK4 and semi-implicit Euler.
"""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest
from conftest import (
    REL,
    assert_rel,
    mount_on_reference_vehicle,
    random_configuration,
    with_spherical_joint,
)

import uvms_pin as up
from uvms_pin.model.resources import shipped_models, shipped_path
from uvms_pin.physics.contact import CompliantPlane, LinearSpring
from uvms_pin.physics.disturbance import SinusoidalDisturbance
from uvms_pin.sim.integrators import RK4, SemiImplicitEuler, python_chart
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System

ERD_ARMS = ("ur5", "panda", "z1")


@pytest.fixture(scope="module", params=["reference", *ERD_ARMS])
def system(request, reference_uvms, tmp_path_factory) -> up.UVMS:
    """The reference model, or an example-robot-data arm mounted on its vehicle (a hard
    dependency: found or the test fails). Each is a case of its own: an arm that fails to
    mount fails its cases, never the reference model's."""
    if request.param == "reference":
        return reference_uvms
    uvms = mount_on_reference_vehicle(request.param, tmp_path_factory.mktemp(request.param))
    assert uvms.n_arm_joints >= 6, request.param
    return uvms


@pytest.mark.parametrize("current", [(0.0, 0.0, 0.0), (0.3, -0.2, 0.1)])
def test_dynamics_match_the_reference(system, current):
    rng = np.random.default_rng(9)
    current = np.array(current)
    uvms = system
    for _ in range(5):
        q = random_configuration(uvms, rng)
        v = rng.normal(scale=0.5, size=uvms.nv)
        tau = rng.normal(scale=5.0, size=uvms.nv)
        tau_ext = rng.normal(scale=2.0, size=uvms.nv)
        for ext in (None, tau_ext):
            _assert_dynamics_match(uvms, q, v, tau, current, ext)


def _assert_dynamics_match(uvms, q, v, tau, current, tau_ext=None) -> None:
    """M, h and forward dynamics of the core equal the reference's at (q, v, tau)."""
    assert_rel(up.mass_matrix(uvms, q), up.mass_matrix(uvms, q, backend="python"))
    assert_rel(
        up.bias_forces(uvms, q, v, current),
        up.bias_forces(uvms, q, v, current, backend="python"),
    )
    assert_rel(
        up.forward_dynamics(uvms, q, v, tau, current, tau_ext),
        up.forward_dynamics(uvms, q, v, tau, current, tau_ext, backend="python"),
    )


def _plants(uvms, rng):
    """Plant pairs (core, python) with each contact kind, a current and a disturbance."""
    current = np.array([0.2, -0.1, 0.05])
    disturbance = SinusoidalDisturbance(rng.normal(size=6), period_s=3.0, phase_rad=0.4)
    contacts = [
        None,
        lambda: LinearSpring(np.array([2.0, 3.0, 5.0])),
        # the tip starts 1 cm inside a tilted plane: pushed back
        lambda: CompliantPlane(np.array([0.3, 0.2, 1.0]), 200.0, 5.0),
    ]
    for make in contacts:
        pair = []
        for backend in ("core", "python"):
            plant = Plant(
                uvms,
                current,
                None if make is None else make(),
                disturbance,
                backend=backend,
            )
            pair.append(plant)
        yield pair


def _attach_inside(plant: Plant, q0: np.ndarray) -> None:
    plant.attach(q0)
    if isinstance(plant.contact, CompliantPlane):
        plant.contact._at = plant.contact._at + 0.01 * plant.contact.normal_world
        plant.__dict__.pop("_compiled", None)


def test_plant_right_hand_side_matches_the_reference(system):
    rng = np.random.default_rng(3)
    uvms = system
    q0 = uvms.neutral_configuration()
    for core, python in _plants(uvms, rng):
        for plant in (core, python):
            _attach_inside(plant, q0)
        for _ in range(3):
            q = q0.copy()
            q[7:] += rng.normal(scale=0.01, size=uvms.nv - 6)
            v = rng.normal(scale=0.3, size=uvms.nv)
            tau = rng.normal(scale=5.0, size=uvms.nv)
            t = float(rng.uniform(0.0, 5.0))
            lam = python.contact_wrench(q, v)
            np.testing.assert_allclose(core.contact_wrench(q, v), lam, rtol=REL, atol=0.0)
            assert_rel(core.acceleration(t, q, v, tau), python.acceleration(t, q, v, tau))
            given = rng.normal(size=6)
            assert_rel(
                core.acceleration(t, q, v, tau, given),
                python.acceleration(t, q, v, tau, given),
            )


def test_plane_pushes_only_inside(reference_uvms):
    q0 = reference_uvms.neutral_configuration()
    plant = Plant(reference_uvms, contact=CompliantPlane(np.array([0.0, 0.0, 1.0]), 100.0))
    plant.attach(q0)
    v = np.zeros(reference_uvms.nv)
    assert not np.any(plant.contact_wrench(q0, v))  # on the surface: depth 0
    _attach_inside(plant, q0)
    lam = plant.contact_wrench(q0, v)
    np.testing.assert_allclose(lam, [0.0, 0.0, -1.0, 0.0, 0.0, 0.0], rtol=1e-12)


@pytest.mark.parametrize("integrator", [RK4(5e-4), SemiImplicitEuler(5e-4)])
def test_advance_over_a_control_period_matches_the_reference(system, integrator):
    rng = np.random.default_rng(4)
    uvms = system
    q0 = uvms.neutral_configuration()
    for core, python in _plants(uvms, rng):
        for plant in (core, python):
            _attach_inside(plant, q0)
        v0 = rng.normal(scale=0.3, size=uvms.nv)
        tau = rng.normal(scale=5.0, size=uvms.nv)
        q_c, v_c = System(core).advance(integrator, 0.1, q0, v0, tau, 0.102)
        q_p, v_p = System(python).advance(integrator, 0.1, q0, v0, tau, 0.102)
        assert_rel(q_c, q_p)
        assert_rel(v_c, v_p)


def test_compiled_chart_matches_pinocchio_from_python(system):
    rng = np.random.default_rng(11)
    uvms = system
    chart = Plant(uvms).compiled.chart
    reference = python_chart(uvms.model)
    for _ in range(5):
        q0 = random_configuration(uvms, rng)
        delta = rng.normal(scale=0.3, size=uvms.nv)
        v = rng.normal(size=uvms.nv)
        for got, expected in zip(chart(q0, delta, v), reference(q0, delta, v), strict=True):
            assert_rel(got, expected)


def test_generic_joints_in_the_articulated_pass_match_the_reference(reference_uvms):
    """A 3-DoF (spherical) joint takes the pass's generic route: same answer as M and h."""
    uvms = with_spherical_joint(reference_uvms, 3)
    assert uvms.model.joints[3].shortname() == "JointModelSpherical"
    rng = np.random.default_rng(12)
    for _ in range(5):
        q = pin.randomConfiguration(uvms.model, -np.ones(uvms.model.nq), np.ones(uvms.model.nq))
        v = rng.normal(scale=0.5, size=uvms.nv)
        tau = rng.normal(scale=5.0, size=uvms.nv)
        current = np.array([0.3, -0.2, 0.1])
        assert_rel(
            up.forward_dynamics(uvms, q, v, tau, current),
            up.forward_dynamics(uvms, q, v, tau, current, backend="python"),
        )


@pytest.mark.parametrize("name", shipped_models())
def test_every_shipped_model_matches_the_reference(name):
    """Each model file uvms-pin ships (vehicles, arm, mounted systems): M, h and forward
    dynamics with and without a current, and the plant with its disturbance (and the spring
    when the model has an end-effector)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", up.ModelWarning)  # e.g. the arm file's dry links
        uvms = up.load_uvms(shipped_path(f"models/{name}.urdf"))
    rng = np.random.default_rng(13)
    for current in (np.zeros(3), np.array([0.3, -0.2, 0.1])):
        for _ in range(3):
            q = random_configuration(uvms, rng)
            v = rng.normal(scale=0.5, size=uvms.nv)
            tau = rng.normal(scale=5.0, size=uvms.nv)
            _assert_dynamics_match(uvms, q, v, tau, current)
    contact = (lambda: LinearSpring(np.full(3, 2.0))) if uvms.has_end_effector else lambda: None
    disturbance = SinusoidalDisturbance(rng.normal(size=6), period_s=3.0)
    current = np.array([0.2, -0.1, 0.05])
    core, python = (
        Plant(uvms, current, contact(), disturbance, backend=b) for b in ("core", "python")
    )
    q0 = uvms.neutral_configuration()
    for plant in (core, python):
        plant.attach(q0)
    v0 = rng.normal(scale=0.3, size=uvms.nv)
    tau = rng.normal(scale=5.0, size=uvms.nv)
    assert_rel(core.acceleration(0.3, q0, v0, tau), python.acceleration(0.3, q0, v0, tau))
    for got, expected in zip(
        System(core).advance(RK4(5e-4), 0.1, q0, v0, tau, 0.102),
        System(python).advance(RK4(5e-4), 0.1, q0, v0, tau, 0.102),
        strict=True,
    ):
        assert_rel(got, expected)
