"""Rigid contacts between moving bodies and fixtures (``[world] moving_contact = "rigid"``
with a ``type = "urdf"`` object): a fixture's link is one side of a point contact, its
joints in the Delassus operator with the other bodies', its joint limits and friction in
the same solve (`uvms_pin.sim.system.fixtures.with_fixtures`), its root link on the
universe (fixed).

A steel ball dropped on the subsea valve's paddle turns the handle, as with the compliant
law, and the ball's and the handle's mechanical energy never rises (the compliant law
stores energy in its spring: it rises there by a millijoule at the impact); a ball dropped
on a fixture's fixed root link comes to rest on it, neither sinking in nor crashing
Pinocchio (which gives no Jacobian for joint 0)."""

from __future__ import annotations

import numpy as np
import pytest
from fixture_helpers import VALVE, lever_urdf
from free_object_helpers import undamped

from uvms_pin.physics.world.fixture import fixture
from uvms_pin.physics.world.free_object import free_object
from uvms_pin.physics.world.world import World
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System

RHO, PERIOD_S, RADIUS_M = 1025.0, 0.002, 0.05
FAR = np.array([30.0, 30.0, -20.0])  # the robot, out of every fixture's reach
#: the compiled step against the reference [m, rad] (measured 8.6e-9 m and 8.1e-9 rad over
#: the drop: the two solvers' tolerances, 1e-10 and 1e-8 m/s)
AGREEMENT_M = 1e-7


def _steel_ball(centre_m) -> object:
    """A 50 mm steel ball without drag (its buoyancy and added mass kept)."""
    pose = (list(centre_m), [0.0, 0.0, 0.0])
    ball = free_object(
        "ball", "sphere", {"radius_m": RADIUS_M}, pose, density_kg_m3=7800.0,
        water_density_kg_m3=RHO,
    )  # fmt: skip
    return undamped(ball)


def _dropped(uvms, body, contact: str, seconds: float, compiled: bool = True):
    """The ball dropped on ``body`` (a fixture) with ``contact`` moving contacts, the robot
    far away: after each period the ball's and the fixture's mechanical energy (kinetic
    with the added mass, plus the ball's net weight's potential) [J], the ball's centre
    height [m] and the fixture's joints (T, nq_f); ``compiled`` False: the Python
    reference's step."""
    ball = _steel_ball(body[1])
    world = World(uvms, [], free=[ball], fixtures=[body[0]], moving_contact=contact)
    system = System(Plant(uvms, free_surface=False, world=world), compiled=compiled)
    integration = system.log.record(RK4(5e-4))["world"]["integration"]
    assert ("one compiled call" in integration) == compiled, integration
    q0 = uvms.neutral_configuration()
    q0[:3] = FAR
    state = system.initial_state(q0, np.zeros(uvms.nv))
    system.start(state)
    layout, weight_N = system.layout, -ball.uvms.net_buoyancy_N
    at_ball, at_fixture = layout.q_slices[1], layout.q_slices[2]
    moving = np.r_[np.arange(*layout.v_slices[1].indices(layout.nv)),
                   np.arange(*layout.v_slices[2].indices(layout.nv))]  # fmt: skip

    def energy(q, v):
        mass = system.mass_matrix(0.0, q)[np.ix_(moving, moving)]
        return 0.5 * v[moving] @ mass @ v[moving] + weight_N * q[at_ball][2]

    q, v, tau = state.q, state.v, np.zeros(uvms.nv)
    energies, heights, joints = [energy(q, v)], [q[at_ball][2]], [q[at_fixture].copy()]
    for k in range(round(seconds / PERIOD_S)):
        q, v = system.advance(RK4(5e-4), k * PERIOD_S, q, v, tau, (k + 1) * PERIOD_S)
        energies.append(energy(q, v))
        heights.append(q[at_ball][2])
        joints.append(q[at_fixture].copy())
    return np.array(energies), np.array(heights), np.array(joints), system


def _valve_and_ball_above_its_paddle():
    # the panel faces +x, the handle's axis; its paddle lies along y at q = 0 and turns
    # towards +z for q > 0: a weight on its -y end turns it
    valve = fixture("panel", VALVE, ([0.0, 0.0, -5.0], [0.0, 0.0, 0.0]), water_density_kg_m3=RHO)
    return valve, (0.065, -0.085, -5.0 + 0.02 + RADIUS_M + 0.002)


# the reference's run is the long one (`make check` leaves it out): the compiled step is checked
# against the reference by test_the_compiled_step_solves_the_fixture_as_the_reference
@pytest.mark.parametrize(
    "compiled",
    [True, pytest.param(False, marks=pytest.mark.slow)],
    ids=["compiled", "reference"],
)
def test_a_ball_dropped_on_the_handle_turns_it_and_never_adds_energy(reference_uvms, compiled):
    energy, _, valve_rad, system = _dropped(
        reference_uvms, _valve_and_ball_above_its_paddle(), "rigid", 0.6, compiled
    )
    assert system.moving_constraints is not None  # the fixture's pairs are rigid rows
    # the compliant law turns it by 0.42 rad in 0.6 s (measured); the rigid one by 0.47
    assert valve_rad[-1, 0] > 0.3
    assert np.max(np.diff(energy)) < 1e-9  # measured 9e-13 J
    assert energy[0] - energy[-1] > 0.5  # the handle's damping and friction took it


def test_the_rigid_and_the_compliant_contact_turn_the_handle_alike(reference_uvms):
    """The rigid contact is the compliant law's limit: the handle's angle after 0.6 s
    agrees within 20 % (0.47 and 0.42 rad measured; the compliant ball sinks 2 mm into the
    paddle and its impact stores and returns energy)."""
    body = _valve_and_ball_above_its_paddle()
    rigid = _dropped(reference_uvms, body, "rigid", 0.6)[2][-1, 0]
    compliant = _dropped(reference_uvms, body, "compliant", 0.6)[2][-1, 0]
    assert abs(rigid - compliant) < 0.2 * compliant


def test_a_ball_dropped_on_a_fixtures_fixed_root_rests_on_it(reference_uvms, tmp_path):
    """The lever's base (a 50 mm cube on the universe, joint 0) carries the ball: its
    centre ends one radius above the cube's top, within the solver's tolerance (the lever
    held by its friction, 2 N m against its weight's 0.98 N m: no potential of its own)."""
    lever = fixture(
        "lever", lever_urdf(tmp_path, friction_Nm=2.0), ([0.0, 0.0, -5.0], [0.0, 0.0, 0.0]),
        water_density_kg_m3=RHO,
    )  # fmt: skip
    top_m = -5.0 + 0.025
    energy, height, _, _ = _dropped(
        reference_uvms, (lever, (-0.01, 0.0, top_m + RADIUS_M + 0.01)), "rigid", 0.4
    )
    assert height.min() > top_m + RADIUS_M - 1e-4
    assert abs(height[-1] - (top_m + RADIUS_M)) < 1e-4
    assert np.max(np.diff(energy)) < 1e-9


def test_the_compiled_step_solves_the_fixture_as_the_reference(reference_uvms):
    """The compiled system (src/uvms_core/moving_constraints.hpp: the paddle's joint joins the
    ball's contact rows with its friction as a box row, by projected Gauss-Seidel to 1e-10
    m/s) against the reference (`fixtures.with_fixtures`, Pinocchio's ADMM to 1e-8 m/s):
    the ball's height and the handle's angle over the 0.6 s of the drop."""
    body = _valve_and_ball_above_its_paddle()
    _, height, valve_rad, _ = _dropped(reference_uvms, body, "rigid", 0.6, compiled=True)
    _, height_ref, valve_ref, _ = _dropped(reference_uvms, body, "rigid", 0.6, compiled=False)
    assert valve_rad[-1, 0] > 0.3  # it turned: the joint was in the solve
    np.testing.assert_allclose(height, height_ref, rtol=0.0, atol=AGREEMENT_M)
    np.testing.assert_allclose(valve_rad, valve_ref, rtol=0.0, atol=AGREEMENT_M)
