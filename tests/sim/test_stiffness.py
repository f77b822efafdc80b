"""Stable at the defaults, or refused before the run with the stiffest mode named: the
integrators' one-step maps on a spring-damper are their own steps; a point mass on a spring
turns unstable where the analysis says (RK4: h omega = 2 sqrt(2) undamped, h c / m = 2.785
overdamped; semi-implicit Euler: h omega = 2); a planted light object and a light wrist on
compliant stops are refused naming them; the shipped scenarios are accepted and record
their stiffest mode."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from conftest import ALPHA5_URDF, run, without_drives
from scipy.optimize import brentq

from uvms_pin.errors import ParameterError, StiffModeError
from uvms_pin.physics.contact import CompliantPlane, LinearSpring
from uvms_pin.physics.joint_stops import JointStops
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.closed_loop import ClosedLoop
from uvms_pin.sim.integrators import RK4, Adaptive, SemiImplicitEuler
from uvms_pin.sim.run import simulate
from uvms_pin.sim.stiff_modes import (
    StiffMode,
    body_mobility,
    candidate_contacts,
    environment_mode,
    stop_modes,
)
from uvms_pin.sim.stiffness import (
    _stiffest,
    check_stiff_modes,
    is_stable,
    largest_stable_step_s,
    system_modes,
)

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"


def _line() -> pin.Model:
    """One prismatic joint along x carrying 1 kg: x'' is the force."""
    model = pin.Model()
    joint = model.addJoint(0, pin.JointModelPX(), pin.SE3.Identity(), "x")
    model.appendBodyToJoint(joint, pin.Inertia(1.0, np.zeros(3), np.eye(3)), pin.SE3.Identity())
    return model


@pytest.mark.parametrize("integrator", [RK4(1e-3), SemiImplicitEuler(1e-3)])
def test_the_one_step_map_is_the_integrators_own_step(integrator):
    mode = StiffMode("a spring", 3.0e4, 40.0, 0.7)
    a = mode.rate_matrix

    def rhs(t, q, v):
        return a[1] @ np.r_[q, v]

    y = np.array([0.013, -0.4])
    h = 7e-4
    q, v = integrator.step(_line(), rhs, 0.0, y[:1], y[1:], h)
    np.testing.assert_allclose(np.r_[q, v], integrator.linear_step(h, a) @ y, rtol=0, atol=1e-15)


def _rk4_real_axis_limit() -> float:
    """x > 0 with R(-x) = 1: RK4's stability interval on the negative real axis."""
    return brentq(lambda x: 1 - x + x**2 / 2 - x**3 / 6 + x**4 / 24 - 1.0, 2.0, 3.0)


def test_a_point_mass_on_a_spring_turns_unstable_where_the_analysis_says():
    k, m = 2.0e4, 0.05
    omega = math.sqrt(k / m)
    undamped = StiffMode("a point mass on a spring", k, 0.0, m)
    np.testing.assert_allclose(undamped.rates, [1j * omega, -1j * omega], rtol=1e-12)
    h_rk4 = largest_stable_step_s(RK4(), undamped)
    assert h_rk4 * omega == pytest.approx(2.0 * math.sqrt(2.0), rel=1e-9)
    assert is_stable(RK4(), 0.999 * h_rk4, undamped)
    assert not is_stable(RK4(), 1.001 * h_rk4, undamped)
    h_euler = largest_stable_step_s(SemiImplicitEuler(), undamped)
    assert h_euler * omega == pytest.approx(2.0, rel=1e-9)
    # overdamped: the fast rate -c/m (nearly) alone, on RK4's real interval (2.785)
    damped = StiffMode("a damper", 1.0, 500.0, m)
    fast = float(np.max(np.abs(damped.rates)))
    assert largest_stable_step_s(RK4(), damped) * fast == pytest.approx(
        _rk4_real_axis_limit(), rel=1e-9
    )
    assert _rk4_real_axis_limit() == pytest.approx(2.785, abs=1e-3)


@pytest.mark.parametrize("integrator", [RK4(step_s=5e-4), SemiImplicitEuler(step_s=5e-4)])
def test_the_pruned_search_picks_the_argmin_of_every_modes_largest_step(integrator):
    # springs of many rates in a shuffled order, the stiffest one's twin ahead of it (equal
    # h*: the first is kept) and one without stiffness (h* inf), as np.argmin picks them
    rng = np.random.default_rng(7)
    springs = np.column_stack([10.0 ** rng.uniform(2, 7, 12), rng.uniform(0, 50, 12)])
    modes = [StiffMode(f"m{i}", k, c, 0.3) for i, (k, c) in enumerate(springs.tolist())]
    stiff = modes[int(np.argmin([largest_stable_step_s(integrator, m) for m in modes]))]
    modes.insert(0, StiffMode("twin", stiff.stiffness, stiff.damping, stiff.mass))
    modes.insert(5, StiffMode("free", 0.0, 0.0, 1.0))
    limits = [largest_stable_step_s(integrator, m) for m in modes]
    assert int(np.argmin(limits)) == 0
    assert _stiffest(integrator, modes) == (0, limits[0])
    assert _stiffest(integrator, [StiffMode("free", 0.0, 0.0, 1.0)] * 2) == (0, math.inf)


def test_a_rk4_run_past_the_largest_step_grows_and_below_it_decays():
    """The same mass on a spring stepped 400 times by RK4 itself, on either side of h*."""
    mode = StiffMode("a spring", 2.0e4, 0.0, 0.05)
    h_max = largest_stable_step_s(RK4(), mode)
    a = mode.rate_matrix

    def rhs(t, q, v):
        return a[1] @ np.r_[q, v]

    for factor, grows in ((0.99, False), (1.01, True)):
        q, v = np.array([1e-3]), np.array([0.0])
        for _ in range(400):
            q, v = RK4().step(_line(), rhs, 0.0, q, v, factor * h_max)
        energy = 0.5 * mode.stiffness * q[0] ** 2 + 0.5 * mode.mass * v[0] ** 2
        assert bool(energy > 0.5 * mode.stiffness * 1e-6) is grows


def _pebble(**changes):
    """push_object with a 1 g pebble (a 1 cm sphere) lying apart on the seabed."""
    box = load_scenario(SCENARIOS / "push_object.toml").raw["world"]["objects"]
    pebble = {
        "type": "sphere",
        "name": "pebble",
        "radius_m": 0.01,
        "position_world_m": [-1.5, 1.5, -9.99],
        "mass_kg": 1e-3,
        **changes,
    }
    return load_scenario(SCENARIOS / "push_object.toml", {"world.objects": [*box, pebble]})


def test_a_planted_light_object_is_refused_before_the_run_naming_it():
    scenario = _pebble()
    with pytest.raises(StiffModeError, match="free object 'pebble'") as caught:
        simulate(scenario, progress=False)
    error = caught.value
    assert isinstance(error, ParameterError)
    step_s = scenario.settings.integrator.step_s  # the scenario's own step
    assert error.step_s == step_s and error.largest_stable_step_s < step_s
    assert error.mode.stiffness == 2.0e4
    # in water: its mass and its added mass (rho V / 2); the stiffest of its modes is
    # its friction's stick spring (c_t = 200 N s/m) against the lighter of what it
    # touches (the pair's 1/m_eff is the sum of both sides': at most the pebble's)
    added = 0.5 * scenario.uvms.water_density_kg_m3 * 4.0 / 3.0 * math.pi * 0.01**3
    assert error.mode.what.endswith("its friction's stick spring")
    assert 0.99 * (1e-3 + added) < error.mode.mass < 1e-3 + added
    for text in ("k = 2e+04 N/m", "m_eff =", f"{step_s:g} s", "largest stable step"):
        assert text in str(error)
    # a 1 kg stone there is accepted
    heavy = _pebble(name="stone", radius_m=0.05, mass_kg=1.0, position_world_m=[-1.5, 1.5, -9.95])
    loop = ClosedLoop(heavy.plant, heavy.settings)
    record = check_stiff_modes(loop.system, loop.system.initial_state(heavy.q0, heavy.v0),
                               heavy.settings.integrator)  # fmt: skip
    assert record["margin"] > 1.0


def test_the_command_line_refuses_it_with_status_2_and_no_traceback(tmp_path):
    scenario = tmp_path / "pebble.toml"
    text = (SCENARIOS / "push_object.toml").read_text()
    scenario.write_text(
        text.replace('"../models/', f'"{SCENARIOS.parent}/models/')
        + '\n[[world.objects]]\ntype = "sphere"\nname = "pebble"\nradius_m = 0.01\n'
        "position_world_m = [-1.5, 1.5, -9.99]\nmass_kg = 0.001\n"
    )
    out = tmp_path / "out"
    result = run("run", str(scenario), "--out", str(out), "--set", 'controller={type="none"}')
    assert result.returncode == 2, result.stderr
    assert "free object 'pebble'" in result.stderr
    assert "Traceback" not in result.stderr
    assert not out.exists()  # refused before the run: nothing written


_ALPHA5_ON_COMPLIANT_STOPS = {
    "joints.stops": "compliant",
    "scenario.duration_s": 1.0,
    "initial.joint_positions_rad": [-0.2, 0.8, 2.2, 0.2],  # within the Alpha 5's limits
}


def test_a_light_wrist_on_compliant_stops_is_refused_naming_its_joint(tmp_path):
    overrides = {
        "scenario.model": str(without_drives(ALPHA5_URDF, tmp_path)),
        **_ALPHA5_ON_COMPLIANT_STOPS,
    }
    with pytest.raises(StiffModeError, match=r"the compliant stop of joint '\w+'") as caught:
        simulate(load_scenario(SCENARIOS / "passive_still_water.toml", overrides), progress=False)
    assert "<armature" in str(caught.value)  # the URDF lacks the drive's inertia: said so
    assert caught.value.mode.units[2] == "kg m^2"
    assert caught.value.mode.mass < 1e-3  # the wrist: ~8e-5 kg m^2


def test_an_adaptive_integrator_is_not_checked():
    scenario = load_scenario(SCENARIOS / "paper_force_tracking.toml")
    assert isinstance(scenario.settings.integrator, Adaptive)
    loop = ClosedLoop(scenario.plant, scenario.settings)
    state = loop.system.initial_state(scenario.q0, scenario.v0)
    record = check_stiff_modes(loop.system, state, scenario.settings.integrator)
    assert record["checked"] is False


@pytest.mark.parametrize("path", sorted(SCENARIOS.glob("*.toml")), ids=lambda p: p.stem)
def test_every_shipped_scenario_is_accepted_at_its_defaults(path):
    scenario = load_scenario(path)
    for robot in getattr(scenario, "robots", (scenario,)):  # [[robots]]: each robot
        loop = ClosedLoop(robot.plant, robot.settings)
        state = loop.system.initial_state(robot.q0, robot.v0)
        record = check_stiff_modes(loop.system, state, robot.settings.integrator)
        if record["checked"] and record["stiffest"] is not None:
            assert record["margin"] > 1.0


def test_the_rollout_records_the_stiffest_mode_and_its_margin():
    """seabed_landing's closest mode: the Alpha 5's jaw against the seabed and the rock,
    its friction's stick spring (k_t = 2e4 N/m, c_t = 200 N s/m; its most mobile corner:
    0.82 kg with the drives' armature), 35.6x its 0.5 ms step (its normal mode at first
    touch, 36.3x, is the next)."""
    scenario = load_scenario(SCENARIOS / "seabed_landing.toml", {"scenario.duration_s": 0.1})
    record = simulate(scenario, progress=False).metadata["stiff_modes"]
    assert record["checked"] and record["integrator"] == "RK4" and record["step_s"] == 5e-4
    stiffest = record["stiffest"]
    assert "link 'alpha_jaw_link' against the fixed world" in stiffest["what"]
    assert stiffest["what"].endswith("its friction's stick spring")
    assert stiffest["stiffness"] == 2.0e4 and stiffest["damping"] == 200.0
    assert stiffest["effective_mass"] == pytest.approx(0.823, abs=0.001)
    # its rates: -c / 2m +- i sqrt(k/m - (c / 2m)^2)
    m = stiffest["effective_mass"]
    decay, turn = 200.0 / (2.0 * m), math.sqrt(2.0e4 / m - (200.0 / (2.0 * m)) ** 2)
    rates = sorted((re, abs(im)) for re, im in stiffest["rates_1_s"])
    assert rates == [pytest.approx((-decay, turn))] * 2
    assert record["margin"] == pytest.approx(35.6, abs=0.1)


def test_the_environment_modes_take_the_end_effectors_mobility():
    """G = J M^-1 J^T diagonal: a plane along z is the mass 1 / G_zz; the paper's spring is
    its fastest axis, omega^2 = max K_i G_ii."""
    mobility = np.diag([1 / 2, 1 / 3, 1 / 4])
    plane = environment_mode(CompliantPlane([0.0, 0.0, 1.0], 500.0, 3.0), mobility)
    assert (plane.stiffness, plane.damping, plane.mass) == (500.0, 3.0, pytest.approx(4.0))
    spring = environment_mode(LinearSpring(np.array([10.0, 20.0, 30.0])), mobility)
    assert spring.stiffness == 30.0 and spring.stiffness / spring.mass == pytest.approx(7.5)


def test_a_stops_inertia_is_the_inverse_of_the_inverse_mass_diagonal():
    stops = JointStops(np.array([-1.0, -1.0]), np.array([1.0, 1.0]), 300.0, 2.0, ("a", "b"))
    mass = np.diag([1.0] * 6 + [0.5, 0.25])
    mass[6, 7] = mass[7, 6] = 0.1  # coupled: I_eff = 1 / (M^-1)_jj, not M_jj
    modes = stop_modes(stops, np.linalg.inv(mass))
    assert [m.what for m in modes] == [
        "the compliant stop of joint 'a'",
        "the compliant stop of joint 'b'",
    ]
    assert modes[0].mass == pytest.approx(0.5 - 0.1**2 / 0.25)
    assert modes[1].mass == pytest.approx(0.25 - 0.1**2 / 0.5)
    assert modes[0].units == ("N m/rad", "N m s/rad", "kg m^2")
    # a joint whose model gives it no drive inertia is told so, one with it is not
    told = stop_modes(stops, np.linalg.inv(mass), np.array([0.0] * 6 + [0.0, 0.01]))
    assert "<armature" in told[0].remedy and "<armature" not in told[1].remedy
    assert "<armature" not in modes[0].remedy  # (the model's armature not given)


def test_the_arm_against_its_own_vehicle_is_a_mode_of_their_relative_motion():
    """With self_collision each arm link (the one jointed to the vehicle aside) meets its
    vehicle: the two material points' relative Jacobian, whose vehicle columns cancel
    (J_a - J_b = [0, J_q]), so 1/m_eff = J_q (M^-1)_qq J_q^T, never below the link's
    mobility with the vehicle clamped, J_q (M_qq)^-1 J_q^T: the vehicle's recoil can only
    make the pair lighter."""
    overrides = {"world.contact.self_collision": True}
    scenario = load_scenario(SCENARIOS / "seabed_landing.toml", overrides)
    loop = ClosedLoop(scenario.plant, scenario.settings)
    system = loop.system
    state = system.initial_state(scenario.q0, scenario.v0)
    modes = system_modes(system, state)
    own = {m.what.split(" against")[0]: m.mass for m in modes if "own vehicle" in m.what}
    # the shoulder is jointed to the vehicle, the Alpha 5's base is a part of it
    assert "link 'alpha_shoulder_link_cob'" not in own and "link 'alpha_base_link_cob'" not in own
    assert "link 'alpha_jaw_link'" in own and "link 'alpha_upper_arm_link_cob'" in own
    model, world = system.plant.uvms.model, system.plant.world
    data = model.createData()
    pin.computeJointJacobians(model, data, state.q[system.layout.q_slices[0]])
    robot = system.layout.v_slices[0]
    mass = system.mass_matrix(0.0, state.q)[robot, robot]
    clamped, joints_only = np.zeros_like(mass), np.zeros_like(mass)
    clamped[6:, 6:] = np.linalg.inv(mass[6:, 6:])
    joints_only[6:, 6:] = np.linalg.inv(mass)[6:, 6:]
    for b, name in enumerate(world.body_names):
        if f"link '{name}'" not in own:
            continue
        pieces = [p for p in world.pieces if p.body == b and p.joint_id > 1]
        relative_mass = 1.0 / body_mobility(model, data, joints_only, pieces)
        clamped_mass = 1.0 / body_mobility(model, data, clamped, pieces)
        assert own[f"link '{name}'"] == pytest.approx(relative_mass, rel=1e-9)
        assert 0.0 < relative_mass <= clamped_mass * (1.0 + 1e-9)


def _handle_mobility_1_kg(system, state) -> float:
    """The valve handle's largest point mobility [1/kg] over its pieces' candidate points,
    by hand: one revolute joint of inertia I (the system's M block, added mass included)
    about the unit axis a through o, a point p moves at a x (p - o) per rad/s:
    |a x (p - o)|^2 / I."""
    fixture = system.fixtures[0]
    model = fixture.uvms.model
    data = model.createData()
    q = state.q[system.layout.q_slices[-1]]
    part = system.layout.v_slices[-1]
    inertia = float(system.mass_matrix(0.0, state.q)[part, part][0, 0])
    pin.forwardKinematics(model, data, q)
    axis, origin = data.oMi[1].rotation[:, 0], data.oMi[1].translation
    worst = 0.0
    for piece in (p for p in fixture.pieces if p.joint_id == 1):
        for point, _ in candidate_contacts(piece):
            lever = np.cross(axis, data.oMi[1].act(point) - origin)
            worst = max(worst, float(lever @ lever) / inertia)
    return worst


def test_a_fixtures_moving_link_is_a_mode_of_its_joints_inertia():
    """A robot link against the valve's handle: the pair's 1/m_eff is the link's (as
    against the panel's fixed plate) plus the handle's, the handle's its points'
    |a x r|^2 / I."""
    scenario = load_scenario(SCENARIOS / "valve_turn.toml")
    loop = ClosedLoop(scenario.plant, scenario.settings)
    state = loop.system.initial_state(scenario.q0, scenario.v0)
    modes = system_modes(loop.system, state)
    handle = {
        m.what.split(" against")[0]: m.mass
        for m in modes
        if "joint 'valve' of fixture 'panel', at first touch" in m.what
    }
    # the panel's plate is on the universe: against it a link moves alone
    alone = {
        m.what.split(" against")[0]: m.mass
        for m in modes
        if "fixture 'panel's base, at first touch" in m.what
    }
    assert set(handle) == set(alone) and len(handle) > 5
    expected = _handle_mobility_1_kg(loop.system, state)
    for link, mass in handle.items():
        assert 1.0 / mass - 1.0 / alone[link] == pytest.approx(expected, rel=1e-9)
    based = [m for m in modes if "fixture 'panel's base" in m.what]
    assert all("moving_contact" in m.remedy for m in based)


def test_a_stiff_fixture_contact_is_refused_naming_the_rigid_remedy():
    """Contacts a hundred times stiffer put the jaw against the handle past its stable step;
    the refusal names the fixture and the rigid moving contact, with which that pair is a
    constraint (no longer a mode)."""
    stiff = {"world.contact.stiffness_N_m": 2.0e6}
    scenario = load_scenario(SCENARIOS / "valve_turn.toml", stiff)
    loop = ClosedLoop(scenario.plant, scenario.settings)
    state = loop.system.initial_state(scenario.q0, scenario.v0)
    with pytest.raises(StiffModeError, match="fixture 'panel'") as caught:
        check_stiff_modes(loop.system, state, scenario.settings.integrator)
    assert 'moving_contact = "rigid"' in str(caught.value)
    rigid = load_scenario(SCENARIOS / "valve_turn.toml", {**stiff, "world.moving_contact": "rigid"})
    loop = ClosedLoop(rigid.plant, rigid.settings)
    modes = system_modes(loop.system, loop.system.initial_state(rigid.q0, rigid.v0))
    assert not any("fixture" in m.what for m in modes)


def test_a_jaws_friction_stick_spring_beyond_the_step_is_refused_naming_it():
    """gripper_close with the contact law's stick-spring damper (200 N s/m) in place of
    its own 20: a finger of ~13 g gives the damper a rate of ~1.5e4 1/s, beyond RK4 at
    the 0.5 ms step. Refused before the run (it rang at the step within the friction cone:
    the held rod was logged spinning about its axis at 0.42 rad/s)."""
    scenario = load_scenario(
        SCENARIOS / "gripper_close.toml", {"world.contact.tangential_damping_N_s_m": 200.0}
    )
    with pytest.raises(StiffModeError, match=r"finger.*against the free object 'rod', its fr"):
        simulate(scenario, progress=False)


def test_a_contacts_modes_are_named_as_what_the_check_assumes_not_as_found():
    """Two objects 2 m apart are checked as if they touched: the damped mode says the depth
    is an assumption ("should it press ... (its working depth)"; it read "167 mm deep", as if
    they overlapped); the third mode is the friction's stick spring, its k_t and c_t."""
    from uvms_pin.physics.world.contact_law import ContactLaw
    from uvms_pin.sim.stiff_modes import Body, contact_modes

    law = ContactLaw()
    first, second = Body("a", 1.0 / 3.0, 0.167), Body("b", 0.5, 0.001)
    touch, pressed, stick = contact_modes("a against b", first, second, law, moving=True)
    assert touch.what == "a against b, at first touch" and touch.damping == 0.0
    assert pressed.what == "a against b, should it press 167 mm deep (its working depth)"
    assert pressed.damping == pytest.approx(law.stiffness_N_m * law.dissipation_s_m * 0.167)
    assert stick.what == "a against b, its friction's stick spring"
    assert (stick.stiffness, stick.damping) == (
        law.tangential_stiffness_N_m,
        law.tangential_damping_N_s_m,
    )
    assert touch.mass == pressed.mass == stick.mass == pytest.approx(1.0 / (1 / 3 + 0.5))
