"""Joint stops: compliant, only past a limit, only pushing; the core's equal to the
reference's."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import REL, continuous_joint_urdf

import uvms_pin as up
from uvms_pin.control.base import ZeroController
from uvms_pin.hydro.params import HydroParams
from uvms_pin.physics.joint_stops import JointStops
from uvms_pin.sim.closed_loop import simulate_closed_loop
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.sensors import SensorConfig, SensorSuite
from uvms_pin.sim.settings import SimulationSettings
from uvms_pin.sim.system import System


def _weightless(uvms):
    """The same UVMS without gravity (no weight, no buoyancy): only the stop holds the arm."""
    model = pin.Model(uvms.model)
    model.gravity = pin.Motion.Zero()
    return uvms.with_model(model)


def test_the_stop_torque_is_zero_inside_the_range_and_pushes_back_outside():
    stops = JointStops(np.array([-1.0, 0.0]), np.array([1.0, np.inf]), 100.0, 2.0)
    q, v = np.zeros(9), np.zeros(8)
    q[7:] = [0.5, 3.0]
    assert not np.any(stops.torque(q, v))
    q[7:] = [1.1, -0.2]
    tau = stops.torque(q, v)
    assert tau[6] == pytest.approx(-100.0 * 0.1) and tau[7] == pytest.approx(100.0 * 0.2)
    # moving back into the range fast: the damper would pull; the stop does not
    v[6:] = [-50.0, 50.0]
    assert np.all(stops.torque(q, v) == 0.0)
    assert stops.at_stop(q).tolist() == [True, True]
    # any penetration pushes, however small: 1 mm rad past either stop at rest
    q[7:], v[6:] = [1.001, -0.001], 0.0
    tau = stops.torque(q, v)
    assert tau[6] == pytest.approx(-100.0 * 0.001) and tau[7] == pytest.approx(100.0 * 0.001)


@pytest.mark.parametrize("joint", [0, 2])
def test_a_joint_at_its_effort_limit_stays_within_the_stop_deflection(reference_uvms, joint):
    uvms = _weightless(reference_uvms)
    stops = JointStops.of_model(uvms.model, stiffness_Nm_rad=200.0, damping_Nm_s_rad=1.0)
    effort = float(uvms.model.effortLimit[6 + joint])
    assert effort > 0.0
    plant = Plant(uvms, joint_stops=stops, free_surface=False)
    q = uvms.neutral_configuration()
    q[:3] = [0.0, 0.0, -5.0]
    q[7 + joint] = stops.upper_rad[joint]
    v, tau = np.zeros(uvms.nv), np.zeros(uvms.nv)
    tau[6 + joint] = effort  # pushing into the stop at the limit of the drive
    deflection = []
    for k in range(300):
        q, v = System(plant).advance(RK4(1e-3), k * 0.01, q, v, tau, (k + 1) * 0.01)
        deflection.append(q[7 + joint] - stops.upper_rad[joint])
    static = effort / stops.stiffness_Nm_rad
    # a step load from rest against a spring never goes past twice its static deflection
    assert max(deflection) <= 2.0 * static
    assert deflection[-1] == pytest.approx(static, rel=0.02)
    # and without the stop the same push carries the joint far past its limit
    free = Plant(uvms, free_surface=False)
    q = uvms.neutral_configuration()
    q[7 + joint] = stops.upper_rad[joint]
    q, v = System(free).advance(RK4(1e-3), 0.0, q, np.zeros(uvms.nv), tau, 1.0)
    assert q[7 + joint] - stops.upper_rad[joint] > 10 * static


def test_the_core_stops_equal_the_reference(reference_uvms):
    uvms = reference_uvms
    stops = JointStops.of_model(uvms.model, 300.0, 3.0)
    core = Plant(uvms, joint_stops=stops, free_surface=False, backend="core")
    python = Plant(uvms, joint_stops=stops, free_surface=False, backend="python")
    assert core.compiled is not None  # the compiled plant carries the stops
    rng = np.random.default_rng(5)
    for _ in range(6):
        q = uvms.neutral_configuration()
        q[7:] = rng.uniform(stops.lower_rad - 0.3, stops.upper_rad + 0.3)
        v, tau = rng.normal(size=uvms.nv), rng.normal(size=uvms.nv)
        a_core = core.acceleration(0.0, q, v, tau)
        a_python = python.acceleration(0.0, q, v, tau)
        assert np.allclose(a_core, a_python, rtol=REL, atol=REL * np.abs(a_python).max())
    bare = Plant(uvms, free_surface=False)
    q = uvms.neutral_configuration()
    v, tau = rng.normal(size=uvms.nv), rng.normal(size=uvms.nv)
    assert np.array_equal(core.acceleration(0.0, q, v, tau), bare.acceleration(0.0, q, v, tau))


def test_a_continuous_joint_has_no_stop_and_the_others_keep_theirs(tmp_path):
    """arm_joint1 continuous: q holds its cos and sin, so the stops of joints 2-4 sit at
    shifted coordinates; core and reference agree, and only those joints are pushed."""

    uvms = up.load_uvms(continuous_joint_urdf(tmp_path, ("arm_joint1",)))
    stops = JointStops.of_model(uvms.model, 300.0, 3.0)
    assert stops.names == ("arm_joint2", "arm_joint3", "arm_joint4")
    assert stops.q_index.tolist() == [9, 10, 11] and stops.v_index.tolist() == [7, 8, 9]
    core = Plant(uvms, joint_stops=stops, free_surface=False, backend="core")
    python = Plant(uvms, joint_stops=stops, free_surface=False, backend="python")
    assert core.compiled is not None
    q = uvms.neutral_configuration()
    q[stops.q_index] = stops.upper_rad + 0.1  # every stopped joint 0.1 rad past its limit
    v, tau = np.zeros(uvms.nv), np.zeros(uvms.nv)
    torque = stops.torque(q, v)
    assert torque[6] == 0.0 and np.allclose(torque[7:], -30.0)
    a_core = core.acceleration(0.0, q, v, tau)
    a_python = python.acceleration(0.0, q, v, tau)
    assert np.allclose(a_core, a_python, rtol=REL, atol=REL * np.abs(a_python).max())


def test_the_stop_spring_energy_is_the_potential_of_its_torque():
    stops = JointStops(np.array([-1.0, 0.0]), np.array([1.0, np.inf]), 100.0, 0.0)
    q = np.zeros(9)
    q[7:] = [0.5, 3.0]
    assert stops.energy_J(q) == 0.0
    q[7:] = [1.1, -0.2]
    assert stops.energy_J(q) == pytest.approx(0.5 * 100.0 * (0.1**2 + 0.2**2))
    # -dU/dq is the (undamped) torque, by central differences
    for j in range(2):
        dq = np.zeros(9)
        dq[7 + j] = 1e-6
        slope = (stops.energy_J(q + dq) - stops.energy_J(q - dq)) / 2e-6
        assert -slope == pytest.approx(stops.torque(q, np.zeros(8))[6 + j], rel=1e-6)


def test_total_energy_does_not_grow_while_a_joint_bounces_on_an_undamped_stop(reference_uvms):
    """Weightless, still water without damping: the arm swings into an undamped stop and
    bounces back. With the stop's spring in the potential energy the logged total stays
    constant (to the integrator's error); without it, it would dip by the stored energy."""
    model = pin.Model(reference_uvms.model)
    model.gravity = pin.Motion.Zero()
    uvms = reference_uvms.with_model(model).with_hydro(
        lambda b: HydroParams(
            b.params.volume_m3, b.params.center_of_buoyancy_m, b.params.added_mass,
            np.zeros(6), np.zeros(6),
        )
    )  # fmt: skip
    stops = JointStops.of_model(uvms.model, stiffness_Nm_rad=50.0, damping_Nm_s_rad=0.0)
    plant = Plant(uvms, joint_stops=stops, free_surface=False)
    q0 = uvms.neutral_configuration()
    q0[:3] = [0.0, 0.0, -5.0]
    q0[7] = stops.upper_rad[0] - 0.05
    v0 = np.zeros(uvms.nv)
    v0[6] = 1.0  # towards the upper stop of joint 1
    settings = SimulationSettings(1.5, RK4(step_s=2e-4), log_period_s=0.01)
    sensors = SensorSuite(uvms.model, SensorConfig(), 1.5, 0)
    rollout = simulate_closed_loop(plant, ZeroController(uvms.nv), sensors, q0, v0, settings)
    past = stops.at_stop(rollout.q)[:, 0]
    assert past.any() and not past[-1]  # it hit the stop and came back
    spring = np.array([stops.energy_J(q) for q in rollout.q])
    total = rollout.total_energy_J
    scale = total[0] - total.min() + rollout.kinetic_energy_J[0]
    assert np.max(total - total[0]) <= 1e-6 * scale
    assert np.max(np.abs(total - total[0])) <= 1e-6 * scale
    # the spring held a real share of the energy at the deepest point of the bounce
    assert spring.max() > 0.1 * rollout.kinetic_energy_J[0]
