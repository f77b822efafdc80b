"""The compiled system's coupled constraint step (src/uvms_core/moving_constraints.hpp) against
the Python reference (`uvms_pin.sim.system.period.constrained` with
`uvms_pin.physics.constraints.moving_contacts`): a robot pressing on a box that rests on the
floor, a ball rolling against the box's other side, every contact rigid."""

from __future__ import annotations

import numpy as np
from conftest import RHO, body_urdf, hydro_xml

from uvms_pin.physics.world.contact_law import ContactLaw
from uvms_pin.physics.world.free_object import free_object
from uvms_pin.physics.world.objects import plane
from uvms_pin.physics.world.world import World
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System

FLOOR_Z = -10.0
PERIOD_S = 2e-3
#: compiled (projected Gauss-Seidel to 1e-10 m/s on the rows' velocities) against the
#: reference (Pinocchio's ADMM to 1e-8 m/s): the periods agree to 1e-7, except where the
#: pusher's contact on the box turns from sliding to sticking (the box on four corners, its
#: frictional problem not unique there): 4.1e-4 rad/s on the box's spin in one period
#: (measured), which the rest of the run carries
AGREEMENT = 1e-3


def _scene(load_body, compiled: bool) -> tuple[System, object]:
    """(the system, its state at t = 0 after `start`): robot-object, object-object and
    object-floor contacts, every body moving, all of them rigid."""
    urdf = body_urdf(
        mass=4.0, inertia=(0.016,) * 3,
        hydro=hydro_xml(4.0 / RHO, added=(2.0,) * 6, lin=(1.0,) * 6),
        collision='<sphere radius="0.1"/>',
    )  # fmt: skip
    pusher = load_body(urdf)
    box = free_object(
        "box", "box", {"size_m": [0.6, 0.4, 0.3]}, ([0.0, 0.0, FLOOR_Z + 0.15], [0, 0, 0.1]),
        density_kg_m3=2.0 * RHO, water_density_kg_m3=RHO,
    )  # fmt: skip
    ball = free_object(
        "ball", "sphere", {"radius_m": 0.2}, ([0.51, 0.03, FLOOR_Z + 0.2], [0.2, 0, 0]),
        density_kg_m3=1.5 * RHO, water_density_kg_m3=RHO, velocity_body=[-0.1, 0, 0, 0, 0.3, 0],
    )  # fmt: skip
    floor = plane("seafloor", [0, 0, FLOOR_Z], [0, 0, 1], 0.6, 0.5)
    world = World(pusher, [floor], ContactLaw(), [box, ball], moving_contact="rigid")
    system = System(Plant(pusher, world=world, free_surface=False), compiled=compiled)
    q = pusher.neutral_configuration()
    q[:3] = [-0.405, 0.02, FLOOR_Z + 0.16]
    state = system.initial_state(q, np.array([0.2, 0.05, -0.02, 0.1, -0.2, 0.3]))
    system.start(state)
    return system, state


def _run(system: System, state, periods: int):
    """The states after each period, the robot pushed along x by 20 N."""
    q, v, out = state.q, state.v, []
    tau = np.array([20.0, 0, 0, 0, 0, 0])
    for k in range(periods):
        q, v = system.advance(RK4(5e-4), k * PERIOD_S, q, v, tau, (k + 1) * PERIOD_S)
        out.append(np.concatenate([q, v]))
    return np.array(out), (q, v)


def test_the_compiled_coupled_step_follows_the_reference(load_body):
    core, core_state = _scene(load_body, compiled=True)
    python, python_state = _scene(load_body, compiled=False)
    assert "one compiled call" in core.log.record(RK4(5e-4))["world"]["integration"]
    compiled_run, (q, v) = _run(core, core_state, 250)
    reference_run, (q_ref, v_ref) = _run(python, python_state, 250)
    np.testing.assert_allclose(compiled_run, reference_run, rtol=0, atol=AGREEMENT)
    # every kind of contact acted at the end: the pusher and the box, the box and the ball,
    # both on the floor; the compiled run's forces read back as the reference's
    (core_sets, core_fixed) = core.moving.found(*core.robot_state(q, v), _objects(core, q, v))
    (ref_sets, ref_fixed) = python.moving.found(
        *python.robot_state(q_ref, v_ref), _objects(python, q_ref, v_ref)
    )
    assert [len(s) for s in core_sets] == [len(s) for s in ref_sets]
    assert len(core_sets[0]) > 0 and len(core_sets[2]) > 0  # pusher|box, box|ball
    assert all(len(f.touch) > 0 for f in core_fixed)
    # the resultant of each pair or object's contacts (a box on four corners is statically
    # indeterminate: how its weight shares among them is not unique, the solvers share it
    # differently)
    for mine, theirs in zip([*core_sets, *core_fixed], [*ref_sets, *ref_fixed], strict=True):
        resultant = mine.force_world_N.sum(axis=0)
        np.testing.assert_allclose(resultant, theirs.force_world_N.sum(axis=0), atol=0.05)
    # each point's normal force is its force along its normal (out of b, towards a), and
    # pushes: both paths, the pairs and the objects on the floor
    for found in [*core_sets, *core_fixed, *ref_sets, *ref_fixed]:
        along = np.einsum("ki,ki->k", found.force_world_N, found.touch.normal_world)
        np.testing.assert_allclose(found.normal_N, along, rtol=0, atol=1e-9)
        assert np.all(found.normal_N >= -1e-9)
        # rigid: the points end touching, not inside (their penetration, not their gap)
        assert np.all(found.touch.depth_m <= 1e-6) and np.all(found.touch.depth_m >= 0.0)
    assert max(float(np.max(f.normal_N)) for f in ref_sets if len(f)) > 1.0


def _objects(system: System, q, v):
    return system.layout.split(q, v)[1:]
