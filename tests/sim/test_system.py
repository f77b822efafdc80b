"""The system of bodies (uvms_pin.sim.system): one state for every body, one right-hand side,
one period step chosen once per integrator, the world's logged signals."""

from __future__ import annotations

from unittest import mock

import numpy as np
import pytest
from conftest import ALPHA5_URDF, ROOT, without_drives

import uvms_pin as up
from uvms_pin.physics.compiled.extension import core_module
from uvms_pin.physics.constraints.joint_limits import JointLimits
from uvms_pin.physics.contact import LinearSpring
from uvms_pin.physics.joint_stops import JointStops
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.compiled.integrator import integrator_to_core
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import Layout, System
from uvms_pin.sim.system import period as period_module

PUSH = ROOT / "scenarios" / "push_object.toml"


def test_a_layout_splits_and_joins_the_state_of_every_body():
    layout = Layout.of([("robot", 11, 10), ("a", 7, 6), ("b", 7, 6)])
    assert (layout.nq, layout.nv) == (25, 22)
    q, v = np.arange(25.0), np.arange(22.0)
    parts = layout.split(q, v)
    assert [p[0].size for p in parts] == [11, 7, 7] and [p[1].size for p in parts] == [10, 6, 6]
    np.testing.assert_array_equal(parts[1][0], q[11:18])
    joined = layout.join(parts)
    np.testing.assert_array_equal(joined.q, q)
    np.testing.assert_array_equal(joined.v, v)


def test_the_robot_alone_is_the_compiled_plants_period_chosen_once(reference_uvms):
    plant = Plant(reference_uvms, np.array([0.2, 0.0, 0.1]), free_surface=False)
    system = System(plant)
    state = system.initial_state(reference_uvms.neutral_configuration(), np.zeros(10))
    assert (system.layout.nq, system.layout.nv) == (11, 10) and system.objects == ()
    system.start(state)
    integrator, tau = RK4(5e-4), np.linspace(-1.0, 1.0, 10)
    step = integrator_to_core(integrator, core_module())
    expected = plant.compiled.advance(0.0, state.q, state.v, tau, 0.002, step)
    with mock.patch.object(
        period_module, "integrator_to_core", wraps=period_module.integrator_to_core
    ) as built:
        q, v = state.q, state.v
        for k in range(3):
            q, v = system.advance(integrator, 0.002 * k, q, v, tau, 0.002 * (k + 1))
            if k == 0:
                np.testing.assert_array_equal(q, expected[0])
                np.testing.assert_array_equal(v, expected[1])
    assert built.call_count == 1  # the period step is chosen at its first use and kept


@pytest.fixture(scope="module")
def push():
    scenario = load_scenario(PUSH)
    system = System(scenario.plant)
    return scenario, system


def test_free_objects_join_the_state_and_each_body_has_its_own_dynamics(push):
    scenario, system = push
    uvms = scenario.uvms
    n = len(system.objects)
    assert n >= 1
    assert (system.layout.nq, system.layout.nv) == (uvms.nq + 7 * n, uvms.nv + 6 * n)
    state = system.initial_state(scenario.q0, scenario.v0)
    system.start(state)
    for obj, (q_o, v_o) in zip(
        system.objects, system.layout.split(state.q, state.v)[1:], strict=True
    ):
        np.testing.assert_array_equal(q_o, obj.q0)
        np.testing.assert_array_equal(v_o, obj.v0)
    # lifted far away from everything: each body alone in the water
    q, v = state.q.copy(), state.v.copy()
    q[:3] += [0.0, 0.0, 50.0]
    for sl in system.layout.q_slices[1:]:
        q[sl][:3] += [40.0 * (sl.start + 1), 0.0, 60.0]
    tau = np.full(uvms.nv, 0.5)
    a = system.acceleration(0.3, q, v, tau)
    robot_q, robot_v = system.robot_state(q, v)
    np.testing.assert_allclose(
        a[: uvms.nv], scenario.plant.acceleration(0.3, robot_q, robot_v, tau), rtol=1e-12
    )
    for obj, (q_o, v_o), sl in zip(
        system.objects, system.layout.split(q, v)[1:], system.layout.v_slices[1:], strict=True
    ):
        expected = up.forward_dynamics(
            obj.uvms, q_o, v_o, np.zeros(6), flow=scenario.plant.water, time_s=0.3,
            free_surface=scenario.plant.free_surface,
        )  # fmt: skip
        np.testing.assert_allclose(a[sl], expected, rtol=1e-12, atol=1e-14)


def test_the_world_is_logged_per_pair_and_per_object(push):
    scenario, system = push
    state = system.initial_state(scenario.q0, scenario.v0)
    system.start(state)
    logged = system.log.signals(state.q, state.v)
    assert logged["world_contact"].size == 9 * len(system.log.contact_pair_names)
    assert logged["free_objects"].size == 13 * len(system.objects)
    np.testing.assert_array_equal(
        logged["free_objects"][:7], system.layout.split(state.q, state.v)[1][0]
    )
    pairs = system.log.record()["world"]["object_pairs"]
    assert logged["free_object_contact"].size == 9 * len(pairs)
    assert system.log.n_columns >= 9 * (len(system.log.contact_pair_names) + len(pairs)) + 13


def test_without_a_world_nothing_more_is_logged(reference_uvms):
    system = System(Plant(reference_uvms, free_surface=False))
    state = system.initial_state(reference_uvms.neutral_configuration(), np.zeros(10))
    assert system.log.signals(state.q, state.v) == {}
    assert system.log.n_columns == 0 and system.moving is None


def test_a_new_start_steps_with_the_plant_as_attached_anew(reference_uvms):
    """The period step is chosen once, but a run's start anchors the contact anew: the
    next period is the compiled plant's with the new anchor, not the first run's."""
    plant = Plant(reference_uvms, contact=LinearSpring(np.full(3, 500.0)), free_surface=False)
    system = System(plant)
    integrator, tau = RK4(5e-4), np.zeros(10)
    first = system.initial_state(reference_uvms.neutral_configuration(), np.zeros(10))
    system.start(first)
    system.advance(integrator, 0.0, first.q, first.v, tau, 0.002)
    q = reference_uvms.neutral_configuration()
    q[:3] += [0.3, -0.2, 0.1]
    second = system.initial_state(q, np.full(10, 0.05))
    system.start(second)
    got = system.advance(integrator, 0.0, second.q, second.v, tau, 0.002)
    step = integrator_to_core(integrator, core_module())
    expected = plant.compiled.advance(0.0, second.q, second.v, tau, 0.002, step)
    np.testing.assert_array_equal(got[1], expected[1])
    # and the spring pulls towards the new anchor: the state moved from the new start alone
    assert np.linalg.norm(got[0][:3] - q[:3]) < 1e-3


@pytest.fixture(scope="module")
def light_bluerov_alpha5(tmp_path_factory):
    """The BlueROV2 + Alpha 5 force task without its drives' armature: light arm links."""
    model = without_drives(ALPHA5_URDF, tmp_path_factory.mktemp("light_alpha5"))
    path = ROOT / "scenarios" / "bluerov_alpha5_force_tracking.toml"
    return load_scenario(path, {"scenario.model": str(model)})


def _released(scenario, **plant_fields):
    """The smallest distance of an arm joint to its limits [rad] over 2 s of the BlueROV2 +
    Alpha 5 released with no input at its scenario's step (RK4, 0.5 ms substeps of a 2 ms
    period: the arm falls onto its limits), or None when the run diverges."""
    uvms = scenario.uvms
    lower, upper = uvms.model.lowerPositionLimit[7:], uvms.model.upperPositionLimit[7:]
    plant = Plant(uvms, free_surface=True, **plant_fields)
    system = System(plant)
    state = system.initial_state(scenario.q0, scenario.v0)
    system.start(state)
    q, v, tau = state.q, state.v, np.zeros(uvms.nv)
    integrator, period, closest = scenario.settings.integrator, 0.002, np.inf
    for k in range(1000):
        q, v = system.advance(integrator, k * period, q, v, tau, (k + 1) * period)
        if not (np.all(np.isfinite(v)) and np.abs(v).max() < 1e3):
            return None
        closest = min(closest, np.min(q[7:] - lower), np.min(upper - q[7:]))
    return closest


def test_joint_limits_as_constraints_hold_where_the_stops_diverge(light_bluerov_alpha5):
    uvms = light_bluerov_alpha5.uvms
    assert _released(light_bluerov_alpha5, joint_stops=JointStops.of_model(uvms.model)) is None
    closest = _released(light_bluerov_alpha5, joint_limits=JointLimits.of_uvms(uvms))
    assert -1e-6 <= closest < 1e-4  # a joint reached its limit, and none went past it


def test_joint_limits_are_either_stops_or_constraints(reference_uvms):
    with pytest.raises(up.ParameterError, match="not both"):
        Plant(
            reference_uvms,
            joint_stops=JointStops.of_model(reference_uvms.model),
            joint_limits=JointLimits.of_uvms(reference_uvms),
        )


@pytest.mark.parametrize(
    "name", ["push_object", "valve_panel", "surfacing", "object_recovery", "hot_stab"]
)
def test_the_columns_a_run_is_sized_for_are_the_columns_it_logs(name):
    """`SystemLog.n_columns` (what the memory check before a run counts) is exactly the
    width of the world's signals a short run logs: the wet fractions, the contact pairs'
    wrenches, the free objects' states and pairs, the fixtures' joints."""
    period = load_scenario(ROOT / "scenarios" / f"{name}.toml").settings.log_period_s
    scenario = load_scenario(
        ROOT / "scenarios" / f"{name}.toml", {"scenario.duration_s": 2 * period}
    )
    system = System(scenario.plant)
    rollout = up.simulate(scenario, progress=False)
    world = {"wet_fraction", "world_contact", "free_objects", "free_object_contact"}
    world |= {fixture.name for fixture in system.fixtures}
    widths = {k: v.reshape(len(v), -1).shape[1] for k, v in rollout.signals.items() if k in world}
    assert widths, f"{name} logs nothing of its world"
    assert system.log.n_columns == sum(widths.values()), widths


def test_the_initial_state_normalises_the_quaternion_alone_and_copies(reference_uvms):
    """A start whose quaternion is not of unit norm is normalised; the position, the joints
    and the velocity stay as given, and the caller's arrays are not changed."""
    system = System(Plant(reference_uvms))
    q0 = reference_uvms.neutral_configuration()
    q0[:3] = [0.5, -0.2, -3.0]
    q0[3:7] = 2.0 * np.array([0.0, 0.0, 0.6, 0.8])
    q0[7:] = np.linspace(0.3, -0.2, reference_uvms.nq - 7)
    v0 = np.linspace(-0.1, 0.1, reference_uvms.nv)
    given = (q0.copy(), v0.copy())
    state = system.initial_state(q0, v0)
    np.testing.assert_allclose(state.q[3:7], [0.0, 0.0, 0.6, 0.8], rtol=1e-15)
    np.testing.assert_array_equal(state.q[:3], given[0][:3])
    np.testing.assert_array_equal(state.q[7:], given[0][7:])
    np.testing.assert_array_equal(state.v, given[1])
    np.testing.assert_array_equal(q0, given[0])
    np.testing.assert_array_equal(v0, given[1])
