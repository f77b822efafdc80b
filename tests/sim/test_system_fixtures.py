"""Fixtures in the system of bodies (uvms_pin.sim.system.fixtures): a fixture's joints hold
below their Coulomb friction (stiction: a constraint, not a smoothed torque) and turn above
it at (tau - c) / I, stop at their limits, never gain energy, and turn when a free object
pushes them; the fixture is stepped in the compiled system of bodies (compliant moving contacts) or
by the Python integrator (rigid ones), and says which."""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin
import pytest
from conftest import ROOT
from fixture_helpers import (
    LEVER_ARM_M,
    LEVER_MASS_KG,
    LEVER_OWN_IYY,
    VALVE,
    double_lever_urdf,
    lever_urdf,
)

from uvms_pin.physics.constraints.joint_limits import JointLimits
from uvms_pin.physics.constraints.step import constrained_velocity
from uvms_pin.physics.world.fixture import fixture
from uvms_pin.physics.world.free_object import free_object
from uvms_pin.physics.world.world import World
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System, fixtures

RHO, PERIOD_S = 1025.0, 0.002
#: the lever's weight's moment about its axis at q = 0 [N m], its inertia [kg m^2]
TORQUE_NM = LEVER_MASS_KG * 9.81 * LEVER_ARM_M
INERTIA = LEVER_MASS_KG * LEVER_ARM_M**2 + LEVER_OWN_IYY
FAR = np.array([30.0, 30.0, -20.0])  # the robot, out of every fixture's reach


def _system(uvms, bodies, free=()) -> System:
    world = World(uvms, [], free=list(free), fixtures=list(bodies))
    return System(Plant(uvms, free_surface=False, world=world))


def _run(system: System, uvms, seconds: float):
    """The fixtures' (q, v) at the end of every period over ``seconds`` from rest, the
    robot far away with no input."""
    q0 = uvms.neutral_configuration()
    q0[:3] = FAR
    state = system.initial_state(q0, np.zeros(uvms.nv))
    system.start(state)
    q, v, tau, integrator = state.q, state.v, np.zeros(uvms.nv), RK4(5e-4)
    at_q, at_v = system.layout.q_slices[-1], system.layout.v_slices[-1]
    out = [(q[at_q].copy(), v[at_v].copy())]
    for k in range(round(seconds / PERIOD_S)):
        q, v = system.advance(integrator, k * PERIOD_S, q, v, tau, (k + 1) * PERIOD_S)
        out.append((q[at_q].copy(), v[at_v].copy()))
    return np.array([s[0] for s in out]), np.array([s[1] for s in out])


def _lever(tmp_path, **urdf):
    path = lever_urdf(tmp_path, **urdf)
    return fixture("lever", path, ([0.0, 0.0, -5.0], [0.0, 0.0, 0.0]), water_density_kg_m3=RHO)


def test_a_joint_loaded_below_its_friction_does_not_creep(reference_uvms, tmp_path):
    lever = _lever(tmp_path, friction_Nm=TORQUE_NM / 0.95)
    q, v = _run(_system(reference_uvms, [lever]), reference_uvms, 1.0)
    assert np.max(np.abs(q - q[0])) < 1e-9
    assert np.max(np.abs(v)) < 1e-9


def test_a_joint_loaded_above_its_friction_turns_at_tau_minus_c_over_i(reference_uvms, tmp_path):
    c = TORQUE_NM / 1.05
    lever = _lever(tmp_path, friction_Nm=c)
    q, v = _run(_system(reference_uvms, [lever]), reference_uvms, 0.1)
    expected = (TORQUE_NM - c) / INERTIA
    assert np.all(np.diff(q[:, 0]) > 0.0)
    measured = v[-1, 0] / 0.1
    assert measured == pytest.approx(expected, rel=0.02)
    # and the angle is the integral of that acceleration
    assert q[-1, 0] == pytest.approx(0.5 * expected * 0.1**2, rel=0.02)


def test_a_fixture_of_two_joints_holds_below_their_friction(reference_uvms, tmp_path):
    """Two coupled joints go through the iterative solver (not the single joint's exact
    step), to a tolerance scaled by their inverse inertias: no creep beyond 1e-9 rad."""
    path = double_lever_urdf(tmp_path, friction_Nm=3.3 * TORQUE_NM)  # the hinge carries 3 m g d
    double = fixture("double", path, ([0.0, 0.0, -5.0], [0.0, 0.0, 0.0]), water_density_kg_m3=RHO)
    assert double.joint_names == ("hinge", "elbow")
    q, v = _run(_system(reference_uvms, [double]), reference_uvms, 0.5)
    assert np.max(np.abs(q - q[0])) < 1e-9 and np.max(np.abs(v)) < 1e-8


def test_a_links_hydrodynamics_element_gives_it_buoyancy(reference_uvms, tmp_path):
    """A <hydrodynamics> element is read (its buoyancy lightens the lever: half its weight
    held by a friction the dry lever turns through); a dry link has none derived from its
    shapes (the slip above would be 17 % slow with its collision box's buoyancy)."""
    c = 0.95 * TORQUE_NM
    buoyant = _lever(tmp_path, friction_Nm=c, volume_m3=0.5 * LEVER_MASS_KG / RHO)
    q, _ = _run(_system(reference_uvms, [buoyant]), reference_uvms, 0.2)
    assert np.max(np.abs(q)) == 0.0
    q_dry, _ = _run(_system(reference_uvms, [_lever(tmp_path, friction_Nm=c)]), reference_uvms, 0.2)
    assert q_dry[-1, 0] > 1e-3


def _energy(lever, q: np.ndarray, v: np.ndarray) -> float:
    model = lever.uvms.model
    data = model.createData()
    kinetic = 0.5 * v @ pin.crba(model, data, q) @ v
    return float(kinetic + pin.computePotentialEnergy(model, data, q))


def test_a_joint_stops_at_its_limit_and_never_gains_energy(reference_uvms, tmp_path):
    upper = 0.2
    lever = _lever(tmp_path, friction_Nm=0.1, damping=0.01, limits=(-0.1, upper))
    q, v = _run(_system(reference_uvms, [lever]), reference_uvms, 0.4)
    assert q[:, 0].max() <= upper + 1e-6  # the solver's tolerance, h times 1e-8 rad/s
    assert q[-1, 0] == pytest.approx(upper, abs=1e-5) and abs(v[-1, 0]) < 1e-6
    energy = np.array([_energy(lever, a, b) for a, b in zip(q, v, strict=True)])
    assert np.max(np.diff(energy)) < 1e-9
    assert energy[-1] < energy[0] - 0.1  # what it fell by went into friction and the stop


@pytest.mark.parametrize("compiled", [True, False])
def test_a_frictionless_joint_stops_at_its_limit_on_either_path(reference_uvms, tmp_path, compiled):
    """No friction, no damping: the limit alone stops the lever (its exact step's limit
    impulse, the only row it has), on the compiled system and on the Python reference:
    never past the limit, at rest on it after the fall, no energy gained."""
    upper = 0.2
    lever = _lever(tmp_path, friction_Nm=0.0, limits=(-0.1, upper))
    world = World(reference_uvms, [], fixtures=[lever])
    system = System(Plant(reference_uvms, free_surface=False, world=world), compiled=compiled)
    q, v = _run(system, reference_uvms, 0.4)
    assert q[:, 0].max() <= upper + 1e-9
    assert q[-1, 0] == pytest.approx(upper, abs=1e-9) and abs(v[-1, 0]) < 1e-9
    energy = np.array([_energy(lever, a, b) for a, b in zip(q, v, strict=True)])
    assert np.max(np.diff(energy)) < 1e-9


def test_a_free_object_falling_on_the_handle_turns_it(reference_uvms):
    # the panel faces +x, the handle's axis; its paddle lies along y at q = 0 and turns
    # towards +z for q > 0: a weight on its -y end turns it
    pose = ([0.0, 0.0, -5.0], [0.0, 0.0, 0.0])
    valve = fixture("panel", VALVE, pose, water_density_kg_m3=RHO)
    radius = 0.05
    ball = free_object(
        "ball", "sphere", {"radius_m": radius}, ([0.065, -0.085, -5.0 + 0.02 + radius + 0.002],
        [0.0, 0.0, 0.0]), density_kg_m3=7800.0, water_density_kg_m3=RHO,
    )  # fmt: skip
    system = _system(reference_uvms, [valve], [ball])
    assert system.layout.names == ("robot", "ball", "panel")
    q, _ = _run(system, reference_uvms, 0.6)
    assert q[-1, 0] > 0.05
    alone = _system(reference_uvms, [valve])
    q_alone, _ = _run(alone, reference_uvms, 0.2)
    assert np.max(np.abs(q_alone)) < 1e-9  # the weightless-on-its-axis handle holds


def test_the_fixtures_are_logged_and_said_how_they_are_stepped(reference_uvms):
    """Compiled with compliant moving contacts (the default); integrated in Python with
    rigid ones, naming why."""
    valve = fixture(
        "panel", VALVE, ([0.0, 0.0, -5.0], [0.0, 0.0, 0.0]), joint_positions={"valve": 0.3},
        water_density_kg_m3=RHO,
    )  # fmt: skip
    system = _system(reference_uvms, [valve])
    q0 = reference_uvms.neutral_configuration()
    q0[:3] = FAR
    state = system.initial_state(q0, np.zeros(reference_uvms.nv))
    assert state.q.size == reference_uvms.nq + 1 and state.q[-1] == 0.3
    logged = system.log.signals(state.q, state.v)
    assert logged["panel"].components == ("valve",) and logged["panel"].values[0] == 0.3
    record = system.log.record(RK4(5e-4))
    assert record["world"]["integration"].startswith("fixtures: one compiled call")
    assert record["world"]["fixtures"][0]["joints"] == ["valve"]
    assert system.log.n_columns == 9 * len(system.log.contact_pair_names) + 1
    world = World(reference_uvms, [], fixtures=[valve], moving_contact="rigid")
    rigid = System(Plant(reference_uvms, free_surface=False, world=world))
    # rigid moving contacts too: the fixture's joints join the compiled solve when touched
    assert rigid.log.record(RK4(5e-4))["world"]["integration"].startswith("fixtures: one compiled")


def test_a_fixture_touched_by_another_sets_row_is_solved_with_it(tmp_path):
    """A row of another set on a fixture's joint (as a rigid contact with the robot would
    be) joins everything into the one solve: the fixture is then not solved apart."""
    lever = _lever(tmp_path, friction_Nm=0.5, limits=(-0.1, 0.2))
    model = fixtures.system_model(pin.Model(), [lever])
    own = fixtures.constraints(1, [lever])
    other = JointLimits((1,), name="other")  # on the fixture's joint, not the fixture's set
    q, v_free, h = np.array([0.2]), np.array([3.0]), PERIOD_S
    mass = lever.uvms.model.inertias[1].mass * LEVER_ARM_M**2 + LEVER_OWN_IYY
    blocks = fixtures.blocks(1, 0, [lever])
    args = (model, np.array([[mass]]), v_free, q)
    apart = fixtures.with_fixtures(constrained_velocity, own, blocks, *args, own, h)
    assert any(b.name == fixtures.FIXTURE_JOINTS for b in apart.rows) and apart.velocity[0] == 0.0
    together = fixtures.with_fixtures(constrained_velocity, own, blocks, *args, (*own, other), h)
    expected = constrained_velocity(*args, (*own, other), h)
    assert {b.name for b in together.rows} == {b.name for b in expected.rows}
    np.testing.assert_array_equal(together.velocity, expected.velocity)


def test_a_robot_started_inside_a_fixture_is_refused_naming_both_and_the_depth():
    """The BlueROV2 placed on the valve panel's front face, its hull 23 cm into the panel:
    refused before the run (it ran as ok, the vehicle flung off at 0.9 m/s), as a robot
    started inside a rock is; the shipped start, clear of it, runs."""
    from uvms_pin.errors import InitialOverlapError
    from uvms_pin.scenario.load import load_scenario
    from uvms_pin.sim.run import simulate

    panel = ROOT / "scenarios" / "valve_panel.toml"
    inside = {"initial.position_world_m": [0.85, -0.156, -2.027], "scenario.duration_s": 0.1}
    with pytest.raises(
        InitialOverlapError, match=r"'base_link' and 'panel\.\w+' overlap by \d+ mm"
    ):
        simulate(load_scenario(panel, inside), progress=False)
    assert simulate(load_scenario(panel, {"scenario.duration_s": 0.1}), progress=False).status.ok


@pytest.mark.parametrize(
    ("q0", "v_free", "stops"),
    [(0.2, 3.0, "limit"), (0.0, 0.01, "friction"), (0.0, 3.0, "slides")],
)
def test_a_fixtures_exact_step_reports_the_impulses_that_changed_its_velocity(
    tmp_path, q0, v_free, stops
):
    """A lever's joint stepped apart (`with_fixtures`, its exact step): what the step
    reports is what it did, as every constraint step's output must be: the generalized
    impulse is M (v+ - v_free), and it is the joint rows' J^T of their (friction, limit)
    impulses. Driven into its upper limit (0.2 rad) at 3 rad/s the limit stops it; at
    0.01 rad/s from q = 0 its 0.5 N m of friction holds it; at 3 rad/s it slides on,
    slowed by the friction's impulse c h."""
    lever = _lever(tmp_path, friction_Nm=0.5, limits=(-0.1, 0.2))
    model = fixtures.system_model(pin.Model(), [lever])
    own, blocks, h = fixtures.constraints(1, [lever]), fixtures.blocks(1, 0, [lever]), PERIOD_S
    mass = np.array([[INERTIA]])
    v = np.array([v_free])
    out = fixtures.with_fixtures(
        constrained_velocity, own, blocks, model, mass, v, np.array([q0]), own, h
    )
    np.testing.assert_allclose(out.generalized_impulse, mass @ (out.velocity - v), atol=1e-15)
    (rows,) = [b for b in out.rows if b.name == fixtures.FIXTURE_JOINTS]
    impulses = out.impulses[fixtures.FIXTURE_JOINTS].reshape(-1, 2)
    np.testing.assert_allclose(
        out.generalized_impulse, rows.jacobian.T @ impulses.sum(axis=1), atol=1e-15
    )
    friction, limit = impulses[0]
    if stops == "limit":
        assert out.velocity[0] <= 1e-12 and limit < -0.1 * mass[0, 0] * v_free
    elif stops == "friction":
        assert abs(out.velocity[0]) <= 1e-15 and limit == 0.0
        assert friction == pytest.approx(-mass[0, 0] * v_free, rel=1e-12)
    else:
        assert abs(limit) <= 1e-15 and friction == pytest.approx(-0.5 * h, rel=1e-12)
        assert out.velocity[0] == pytest.approx(v_free - 0.5 * h / mass[0, 0], rel=1e-12)


def test_a_free_object_started_inside_a_fixture_is_refused_or_moved_out():
    """A ball (r = 5 cm) centred in the valve panel's 2 cm board: 6 cm deep in it, refused
    naming both; with initial_overlap = "separate" moved out by that depth along the board's
    normal (x) before the run, which then runs."""
    import tomllib

    from uvms_pin.errors import InitialOverlapError
    from uvms_pin.scenario.load import load_scenario
    from uvms_pin.sim.run import simulate

    panel = ROOT / "scenarios" / "valve_panel.toml"
    ball = {"type": "sphere", "name": "ball", "radius_m": 0.05,
            "position_world_m": [0.86, -0.156, -1.85], "density_kg_m3": 1100.0}  # fmt: skip
    objects = [*tomllib.loads(panel.read_text())["world"]["objects"], ball]
    inside = {"world.objects": objects, "scenario.duration_s": 0.1}
    with pytest.raises(InitialOverlapError, match=r"'panel' and 'ball' overlap by 60 mm"):
        simulate(load_scenario(panel, inside), progress=False)
    moved = simulate(
        load_scenario(panel, {**inside, "world.initial_overlap": "separate"}), progress=False
    )
    assert moved.status.ok
    (move,) = moved.metadata["world"]["world"]["initial_overlap"]["moved"]
    assert move["object"] == "ball" and move["bodies"] == ["panel", "ball"]
    assert move["depth_m"] == pytest.approx(0.06, abs=1e-9)
    start = moved.signals["free_objects"].reshape(len(moved), -1, 13)[0, 0, :3]
    # out of the board (x 0.85 .. 0.87) on either side, touching it
    assert abs(start[0] - 0.86) == pytest.approx(0.06, abs=1e-9)
    np.testing.assert_allclose(start[1:], [-0.156, -1.85], atol=1e-12)


def test_the_robots_start_is_checked_against_a_fixture_with_its_own_pieces_only():
    """The robot's check against the fixtures (`overlap.robot_clear_of_fixtures`) reads the
    robot's pieces alone: a large free ball (r = 0.9 m), the first object, 5 m from the
    robot and the panel, starts clear of everything and runs (the ball's sphere placed by
    the robot's kinematics would lie 13 cm deep in the panel's handle)."""
    import tomllib

    from uvms_pin.scenario.load import load_scenario
    from uvms_pin.sim.run import simulate

    panel = ROOT / "scenarios" / "valve_panel.toml"
    ball = {"type": "sphere", "name": "ball", "radius_m": 0.9,
            "position_world_m": [-4.0, 0.0, -1.85], "density_kg_m3": 1100.0}  # fmt: skip
    objects = [ball, *tomllib.loads(panel.read_text())["world"]["objects"]]
    # rigid: the compliant law between the 3.4 t ball and the 0.6 kg handle is refused as
    # stiff before the run (any pair that may touch is weighed)
    clear = {"world.objects": objects, "world.moving_contact": "rigid", "scenario.duration_s": 0.1}
    assert simulate(load_scenario(panel, clear), progress=False).status.ok


#: the lever's limits in the long-period tests [rad]: released at 0, 0.2 rad from the upper
LONG_PERIOD_LIMITS = (-0.1, 0.2)


def _lever_at_period_ends(uvms, tmp_path, period_s, periods, compiled=True, margin=None):
    """The frictionless lever (limits -0.1 and 0.2 rad, released at 0) at each period's end
    over ``periods`` periods of ``period_s`` (``margin``: its limits' selection margin [rad]
    instead of the fixtures' default)."""
    lever = _lever(tmp_path, friction_Nm=0.0, limits=LONG_PERIOD_LIMITS)
    world = World(uvms, [], fixtures=[lever])
    system = System(Plant(uvms, free_surface=False, world=world), compiled=compiled)
    if margin is not None:
        system.fixture_constraints = tuple(
            dataclasses.replace(c, margin=margin) if isinstance(c, JointLimits) else c
            for c in system.fixture_constraints
        )
    q0 = uvms.neutral_configuration()
    q0[:3] = FAR
    state = system.initial_state(q0, np.zeros(uvms.nv))
    system.start(state)
    q, v, tau = state.q, state.v, np.zeros(uvms.nv)
    at = system.layout.q_slices[-1]
    angles = []
    for k in range(periods):
        q, v = system.advance(RK4(5e-4), k * period_s, q, v, tau, (k + 1) * period_s)
        angles.append(float(q[at][0]))
    return np.array(angles)


@pytest.mark.parametrize("period_s", [0.05, 0.3])
def test_a_long_control_period_still_stops_the_lever_on_its_limit(
    reference_uvms, tmp_path, period_s
):
    """The limit is solved at each period's end (docs/physics.md): a lever released 0.2 rad
    from its limit (a pendulum of 0.75 s at that swing) reaches it within the first period
    and rests on it, never past it at a period's end, with periods up to 0.3 s."""
    upper = LONG_PERIOD_LIMITS[1]
    angles = _lever_at_period_ends(reference_uvms, tmp_path, period_s, round(1.2 / period_s))
    assert angles.max() <= upper + 1e-9
    assert angles[-1] == pytest.approx(upper, abs=1e-9)


@pytest.mark.parametrize("compiled", [True, False], ids=["compiled", "python"])
@pytest.mark.parametrize("period_s", [0.375, 0.5])
def test_a_period_longer_than_the_swing_never_ends_past_a_limit(
    reference_uvms, tmp_path, period_s, compiled
):
    """A period as long as the lever's half swing (0.375 s): its smooth step swings it from
    0 through its upper limit to pi and ends nearly at rest there, no impulse needed at that
    end. The limit is a row all the same (the period's travel reaches it): the joint moves
    from q0 with v+, inside its limits. Before, it kept the smooth step's end, 2.9 rad past
    the limit, on the compiled system and the Python reference alike. (Within such a period
    what reverses is lost: the lever then jumps between its limits, docs/physics.md.)"""
    lower, upper = LONG_PERIOD_LIMITS
    angles = _lever_at_period_ends(reference_uvms, tmp_path, period_s, 6, compiled)
    assert np.all((angles >= lower - 1e-9) & (angles <= upper + 1e-9)), angles


def test_the_compiled_system_selects_fixture_limits_with_the_python_margin(
    reference_uvms, tmp_path
):
    """A fixture joint's limit is a row once its gap is at most h |v| + the margin of the
    fixtures' `JointLimits`; the compiled system is given that margin, not a copy of its
    default. With a margin of 0.5 rad the lever's limits (0.1 and 0.2 rad away) are rows from
    the first period: each period then ends at q0 + h v+, not at the smooth step's end, and
    the two paths agree; with the default, far from its limits, the lever swings by the
    smooth step."""
    lower, upper = LONG_PERIOD_LIMITS
    runs = {
        (compiled, margin): _lever_at_period_ends(
            reference_uvms, tmp_path, 0.01, 5, compiled, margin
        )
        for compiled in (True, False)
        for margin in (None, 0.5)
    }
    for margin in (None, 0.5):
        np.testing.assert_allclose(runs[True, margin], runs[False, margin], rtol=0, atol=1e-9)
    assert np.max(np.abs(runs[True, 0.5] - runs[True, None])) > 1e-4
    assert np.all((runs[True, 0.5] > lower) & (runs[True, 0.5] < upper))
