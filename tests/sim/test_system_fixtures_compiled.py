"""The compiled contact search of a system with fixtures (uvms_pin.physics.compiled.moving.
search_compiled, uvms_pin.physics.compiled.moving.PairSearch): the core's PiecePairs finds
the same touching pairs, points, normals, depths and forces as the reference's
`PiecePairs.forces` (the same arithmetic: to 1e-12), for the robot's pieces and a free
object's against a fixture's moving link, with friction anchors set; a run with it follows
the reference's run; the "python" backend and the Python integration asked for keep the
reference's search."""

from __future__ import annotations

import numpy as np
import pytest
from fixture_helpers import VALVE, double_lever_urdf, lever_urdf

from uvms_pin.errors import ParameterError
from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.compiled.extension import core_module
from uvms_pin.physics.compiled.moving import PairSearch, piece_pairs_to_core
from uvms_pin.physics.dynamics import dynamics_of
from uvms_pin.physics.world.fixture import fixture
from uvms_pin.physics.world.free_object import free_object
from uvms_pin.physics.world.world import World
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System

RHO, PERIOD_S, TOL = 1025.0, 0.002, 1e-12
PANEL_POSE = ([0.0, 0.0, -5.0], [0.0, 0.0, 0.0])


def _ball(z_above_m: float = 0.002):
    radius = 0.05
    where = [0.065, -0.085, -5.0 + 0.02 + radius + z_above_m]
    return free_object(
        "ball", "sphere", {"radius_m": radius}, (where, [0.0, 0.0, 0.0]), density_kg_m3=7800.0,
        water_density_kg_m3=RHO,
    )  # fmt: skip


def _system(uvms, *, backend: str = "core", compiled: bool = True, ball=None) -> System:
    valve = fixture("panel", VALVE, PANEL_POSE, water_density_kg_m3=RHO)
    world = World(uvms, [], free=[ball or _ball()], fixtures=[valve])
    plant = Plant(uvms, free_surface=False, world=world, backend=backend)
    return System(plant, compiled=compiled)


def _robot_on_the_paddle(system: System, uvms) -> np.ndarray:
    """The robot's q with its last piece's centre (the jaw's) 1 cm above the centre of the
    panel's piece on the valve joint (the two overlap): a robot-fixture pair that touches."""
    moving = system.moving
    q = uvms.neutral_configuration()
    moving._kinematics(q, np.zeros(uvms.nv), moving.initial_states())
    own = moving.moving.sets[1].pairs  # the robot against the panel
    jaw = own.pieces_a[-1]
    paddle = next(p for p in own.pieces_b if p.joint_id > 0)
    centre = moving.uvms_data.oMi[jaw.joint_id].act(jaw.placement_in_joint.translation)
    target = moving.datas[-1].oMi[paddle.joint_id].act(paddle.placement_in_joint.translation)
    q[:3] += target - centre + np.array([0.0, 0.0, 0.01])
    return q


def _assert_same(python, core) -> None:
    assert len(python) == len(core) > 0
    np.testing.assert_array_equal(core.pair, python.pair)
    for name in ("piece", "obj", "corner"):
        np.testing.assert_array_equal(getattr(core.touch, name), getattr(python.touch, name))
    for name in ("point_world_m", "normal_world", "depth_m", "velocity_world_m_s"):
        x, y = getattr(python.touch, name), getattr(core.touch, name)
        np.testing.assert_allclose(y, x, rtol=TOL, atol=TOL * max(1.0, np.abs(x).max()))
    for name in ("force_world_N", "normal_N", "stretch_m", "material_m"):
        x, y = getattr(python, name), getattr(core, name)
        np.testing.assert_allclose(y, x, rtol=TOL, atol=TOL * max(1.0, np.abs(x).max()))
    np.testing.assert_array_equal(core.sticking, python.sticking)


def test_the_compiled_search_finds_the_references_contacts_with_anchors(reference_uvms):
    system = _system(reference_uvms, ball=_ball(z_above_m=-0.004))  # the ball 4 mm in
    sets = system.moving.moving.sets
    assert [(s.a, s.b) for s in sets] == [(-1, 0), (-1, 1), (0, 1)]
    assert all(isinstance(s.search, PairSearch) for s in sets)
    q = _robot_on_the_paddle(system, reference_uvms)
    states = system.moving.initial_states()
    v = np.linspace(-0.2, 0.3, reference_uvms.nv)
    states[-1][1][:] = 0.7  # the valve turning
    # anchors set at one state, the contacts compared at the next (stretched friction)
    system.moving.settle(q, v, states)
    assert any(s.memory.anchors for s in sets)
    q_next = q.copy()
    q_next[:3] += [0.002, -0.001, 0.0005]
    states[-1][0][:] += 0.01
    system.moving._kinematics(q_next, v, states)
    data = system.moving.moving._datas(system.moving.uvms_data, system.moving.datas)
    touching = 0
    for s in sets:
        python = s.pairs.forces(data(s.a), data(s.b), s.memory)
        core = s.search(data(s.a), data(s.b), s.memory)
        if len(python):
            _assert_same(python, core)
            touching += 1
        else:
            assert len(core) == 0
    assert touching == 2  # the robot and the ball, each on the panel


def test_the_search_is_the_references_in_a_python_run_or_on_the_python_backend(reference_uvms):
    for system in (
        _system(reference_uvms, compiled=False),
        _system(reference_uvms, backend="python"),
    ):
        assert all(s.search is None for s in system.moving.moving.sets)


def _run(system: System, uvms, seconds: float) -> np.ndarray:
    q0 = uvms.neutral_configuration()
    q0[:3] = [30.0, 30.0, -20.0]  # the robot far away; the ball falls on the handle
    state = system.initial_state(q0, np.zeros(uvms.nv))
    system.start(state)
    q, v, tau, integrator = state.q, state.v, np.zeros(uvms.nv), RK4(5e-4)
    out = [q.copy()]
    for k in range(round(seconds / PERIOD_S)):
        q, v = system.advance(integrator, k * PERIOD_S, q, v, tau, (k + 1) * PERIOD_S)
        out.append(q.copy())
    return np.array(out)


def test_the_compiled_system_follows_the_reference(reference_uvms):
    """The ball falls on the handle and turns it: the compiled system of bodies (one call a
    period: the fixture's joints, its contacts, its friction and limits by their exact
    step) and the reference's Python integration agree to rounding amplified over 0.3 s of
    contact (1e-9 rad on the valve, 1e-9 m on the ball)."""
    compiled_system = _system(reference_uvms)
    assert not isinstance(compiled_system.compiled, Fallback)
    compiled = _run(compiled_system, reference_uvms, 0.3)
    reference = _run(_system(reference_uvms, compiled=False), reference_uvms, 0.3)
    assert compiled[-1, -1] > 0.01  # the valve turned
    np.testing.assert_allclose(compiled, reference, rtol=0.0, atol=1e-9)


def _compiled_as_reference(uvms, free: list, fixtures: list, seconds: float) -> np.ndarray:
    """The system of ``free`` objects and ``fixtures`` run by the compiled system (one call a
    period) and by the reference's Python integration: they agree to 1e-9 (asserted); the
    compiled run's states (`_run`)."""

    def system(compiled: bool) -> System:
        world = World(uvms, [], free=free, fixtures=fixtures)
        return System(Plant(uvms, free_surface=False, world=world), compiled=compiled)

    core = system(True)
    assert not isinstance(core.compiled, Fallback)
    compiled = _run(core, uvms, seconds)
    np.testing.assert_allclose(compiled, _run(system(False), uvms, seconds), rtol=0.0, atol=1e-9)
    return compiled


def _lever_and_ball(
    tmp_path, friction_Nm: float, *, name: str = "lever", x_m: float = 0.0, ball_at=(0.02, 0.077)
):
    """A lever fixture (limits -0.05 and 0.3 rad) at (``x_m``, 0, -5 m) and a steel ball
    (r = 5 cm) at (x, z + 5 m) = ``ball_at``: by default 2 mm above the lever's fixed base."""
    lever = fixture(
        name, lever_urdf(tmp_path, friction_Nm=friction_Nm, limits=(-0.05, 0.3)),
        ([x_m, 0.0, -5.0], [0.0, 0.0, 0.0]), water_density_kg_m3=RHO,
    )  # fmt: skip
    ball = free_object(
        "ball", "sphere", {"radius_m": 0.05}, ([ball_at[0], 0.0, -5.0 + ball_at[1]], [0, 0, 0]),
        density_kg_m3=7800.0, water_density_kg_m3=RHO,
    )  # fmt: skip
    return lever, ball


@pytest.mark.parametrize("friction_Nm", [0.2, 2.0])
def test_a_ball_on_a_fixtures_fixed_base_and_lever_as_the_reference(
    reference_uvms, tmp_path, friction_Nm
):
    """A ball dropped on a lever's fixed base (a piece on the universe, joint 0), the lever
    loaded by its own weight (0.98 N m): the base carries the ball (it sinks 4.4 mm into
    the compliant law), the lever is held by its friction at 2 N m and falls to its limit
    at 0.2 N m. The compiled system and the reference agree to 1e-9 over 0.5 s (measured
    4e-17)."""
    lever, ball = _lever_and_ball(tmp_path, friction_Nm)

    compiled = _compiled_as_reference(reference_uvms, [ball], [lever], 0.5)
    ball_z = compiled[:, reference_uvms.nq + 2]
    assert ball_z.min() > -5.0 + 0.025 + 0.05 - 5e-3  # carried: no deeper than the law's sink
    lever_rad = compiled[:, -1]
    if friction_Nm > 1.0:
        assert np.max(np.abs(lever_rad)) < 1e-9  # held by its friction, not creeping
    else:
        assert lever_rad.max() > 0.29  # turned to its 0.3 rad limit ...
        assert lever_rad.max() < 0.3 + 1e-6  # ... and held there


def test_a_ball_on_the_second_of_two_fixtures_turns_it_as_the_reference(reference_uvms, tmp_path):
    """Two levers held by 2 N m of friction against their own weight's 0.98 N m (the first
    1 m away along x), a steel ball dropped 2 mm onto the second's arm: the ball's pairs
    with each fixture are their own set (the second fixture's side after the free objects
    and the first fixture), so its 35 N (3.5 N m) turns the second lever and not the first,
    on both backends alike (to 1e-9 over 0.3 s)."""
    far, _ = _lever_and_ball(tmp_path, friction_Nm=2.0, name="far_lever", x_m=1.0)
    lever, ball = _lever_and_ball(tmp_path, friction_Nm=2.0, ball_at=(0.1, 0.01 + 0.052))
    compiled = _compiled_as_reference(reference_uvms, [ball], [far, lever], 0.3)
    far_rad, lever_rad = compiled[:, -2], compiled[:, -1]
    assert lever_rad.max() > 0.05  # pushed down by the ball
    np.testing.assert_allclose(far_rad, 0.0, atol=1e-9)  # held: nothing touches it


@pytest.mark.parametrize("field", ["placements_a", "velocities_b"])
def test_a_side_with_bad_kinematics_is_refused(reference_uvms, field):
    system = _system(reference_uvms)
    pairs = piece_pairs_to_core(system.moving.moving.sets[0].pairs, core_module())
    njoints = reference_uvms.model.njoints
    args = {
        "placements_a": np.zeros((njoints, 12)), "velocities_a": np.zeros((njoints, 6)),
        "placements_b": np.zeros((7, 12)), "velocities_b": np.zeros((7, 6)),
    }  # fmt: skip
    args[field] = np.zeros((1, 5))
    with pytest.raises(ParameterError, match="side"):
        pairs.forces(*args.values(), system.moving.moving.sets[0].memory)


@pytest.mark.parametrize(
    "urdf",
    [
        lambda d: double_lever_urdf(d, friction_Nm=0.3),
        lambda d: lever_urdf(
            d,
            friction_Nm=0.3,
            damping=0.2,
            joint_type="prismatic",
            limits=(-0.02, 0.05),
            volume_m3=2e-4,
        ),
    ],
    ids=["two coupled joints", "prismatic in the water"],
)
def test_a_fixture_falling_on_its_own_as_the_reference(reference_uvms, tmp_path, urdf):
    """Fixtures of other shapes, no contact: two coupled revolute joints with friction
    below their load, each reaching a limit; a prismatic joint with damping, friction and
    a displaced volume (buoyancy and added mass). The compiled system and the reference
    agree to 1e-9 over 0.6 s, and the joints moved."""
    body = fixture(
        "f", urdf(tmp_path), ([0.0, 0.0, -5.0], [0.3, 0.0, 0.0]), water_density_kg_m3=RHO
    )

    compiled = _compiled_as_reference(reference_uvms, [], [body], 0.6)
    joints = compiled[:, reference_uvms.nq :]
    assert np.max(np.abs(joints[-1] - joints[0])) > 1e-3


def test_the_core_refuses_a_fixture_with_bad_parts(reference_uvms):
    system = _system(reference_uvms)
    (valve,) = system.fixtures
    core = core_module()
    plant, dynamics = system.plant.compiled, dynamics_of(valve.uvms).core
    lower, upper = valve.limits
    for damping, coulomb, match in (
        (np.zeros(2), valve.coulomb, "damping, coulomb, lower and upper"),
        (valve.damping, -valve.coulomb - 1.0, ">= 0"),
    ):
        with pytest.raises(ParameterError, match=match):
            core.System(plant, [], [dynamics], [damping], [coulomb], [lower], [upper])
    with pytest.raises(ParameterError, match="one per fixture"):
        core.System(plant, [], [dynamics], [], [valve.coulomb], [lower], [upper])


@pytest.mark.parametrize("compiled", [False, True], ids=["python", "core"])
def test_on_rigid_pairs_a_fixtures_fixed_base_carries_a_ball_while_its_lever_turns(
    reference_uvms, tmp_path, compiled
):
    """Rigid moving pairs: a ball dropped 2 mm onto a lever's fixed base (a piece on the
    universe, joint 0) rests there, while the lever beside it (0.2 N m of friction against
    its own weight's 0.98 N m) falls to its 0.3 rad limit: the base's piece does not turn
    with the lever's joint, so the ball stays where it landed."""
    lever, ball = _lever_and_ball(tmp_path, friction_Nm=0.2)
    world = World(reference_uvms, [], free=[ball], fixtures=[lever], moving_contact="rigid")
    system = System(Plant(reference_uvms, free_surface=False, world=world), compiled=compiled)
    states = _run(system, reference_uvms, 0.5)
    at = reference_uvms.nq
    landed = states[len(states) // 5 :, at : at + 3]  # after 0.1 s
    assert states[:, -1].max() > 0.29  # the lever turned to its limit
    np.testing.assert_allclose(landed[:, 2], -5.0 + 0.025 + 0.05, rtol=0, atol=1e-4)
    assert np.ptp(landed, axis=0).max() < 1e-4  # the ball did not move
