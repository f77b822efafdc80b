"""The friction of a pair of moving pieces (`uvms_pin.physics.world.pairs`): its stretch is
measured from a's material point of the period's start, and carried over at the period's end
to the new contact point."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import RHO, body_urdf, hydro_xml

from uvms_pin.physics.compiled.extension import core_module
from uvms_pin.physics.compiled.moving import PairSearch
from uvms_pin.physics.world.contact_law import ContactLaw
from uvms_pin.physics.world.free_object import free_object
from uvms_pin.physics.world.world import FrictionMemory, World
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System


def _body(load_body, collision: str):
    """A 4 kg neutrally buoyant one-body robot of the ``collision`` shape."""
    return load_body(
        body_urdf(mass=4.0, inertia=(0.016,) * 3, hydro=hydro_xml(4.0 / RHO), collision=collision)
    )


def _touching(load_body):
    """A sphere robot 5 mm into a free sphere's side, both at rest."""
    pusher = _body(load_body, '<sphere radius="0.1"/>')
    ball = free_object(
        "ball", "sphere", {"radius_m": 0.2}, ([0.0, 0.0, -5.0], [0, 0, 0]),
        density_kg_m3=RHO, water_density_kg_m3=RHO,
    )  # fmt: skip
    system = System(Plant(pusher, world=World(pusher, [], ContactLaw(), [ball])))
    q = pusher.neutral_configuration()
    q[:3] = [-0.295, 0.0, -5.0]
    return system, q, ball


def test_a_sticking_pair_s_stretch_is_carried_over_to_the_new_contact_point(load_body):
    system, q, ball = _touching(load_body)
    moving = system.moving
    states = [(ball.q0.copy(), np.zeros(6))]
    v = np.zeros(6)
    v[1] = 0.01  # sliding sideways along the ball: a stretch builds
    moving.settle(q, np.zeros(6), states)  # anchored at rest
    (memory,) = [s.memory for s in moving.moving.sets]
    assert list(memory.material) == [(0, 0, -1)]
    # the robot rolled about its centre and moved: the contact point moved on it
    turned = q.copy()
    turned[1] += 2e-4
    turned[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(0.0, 0.0, 0.02)).coeffs()
    (before,), _ = moving.found(turned, v, states)
    assert before.sticking.all() and np.linalg.norm(before.stretch_m) > 1e-5
    moving.settle(turned, v, states)
    (after,), _ = moving.found(turned, v, states)
    np.testing.assert_allclose(after.stretch_m, before.stretch_m, rtol=0, atol=1e-15)
    np.testing.assert_allclose(after.force_world_N, before.force_world_N, rtol=1e-12)
    # the material point is now the one at the contact, in the robot's joint frame
    data = system.plant.uvms.model.createData()
    pin.forwardKinematics(system.plant.uvms.model, data, turned)
    x = after.touch.point_world_m[0]
    np.testing.assert_allclose(memory.material[(0, 0, -1)], data.oMi[1].actInv(x), atol=1e-15)


@pytest.mark.parametrize("searched_by", ["reference", "core"])
def test_a_slipping_pair_slips_on_above_mu_k_and_a_sticking_one_holds_up_to_mu_s(
    load_body, searched_by
):
    """Coulomb's static-kinetic hysteresis, pair by pair: the robot 5 mm into the ball
    (N = k delta = 100 N, nothing closing) sliding sideways at 0.275 m/s, so that the trial
    friction c_t v_t = 55 N lies between mu_k N = 50 N and mu_s N = 60 N. A pair that stuck
    over the last period (its memory) holds: f_t is the trial force. One that slipped slips
    on: f_t is mu_k N, along the trial force. The core's search chooses as the reference."""
    system, q, ball = _touching(load_body)
    law = system.plant.world.law
    (pairs,) = system.moving.moving.sets
    mu_s, mu_k = ball.friction_static, ball.friction_kinetic
    speed = 0.5 * (mu_s + mu_k) * law.stiffness_N_m * 0.005 / law.tangential_damping_N_s_m
    v = np.zeros(6)
    v[1] = speed
    states = system.moving.initial_states()
    system.moving._kinematics(q, v, states)
    data = system.moving.moving._datas(system.moving.uvms_data, system.moving.datas)
    search = pairs.pairs.forces
    if searched_by == "core":
        search = PairSearch(pairs.pairs, core_module())
    normal_N = law.stiffness_N_m * 0.005
    for slipped in (False, True):
        memory = FrictionMemory(slipping={0} if slipped else set())
        found = search(data(pairs.a), data(pairs.b), memory)
        assert found.normal_N[0] == pytest.approx(normal_N, rel=1e-9)
        f_t = found.force_world_N[0] - normal_N * found.touch.normal_world[0]
        trial_N = law.tangential_damping_N_s_m * speed
        assert mu_k * normal_N < trial_N < mu_s * normal_N
        assert bool(found.sticking[0]) is not slipped
        expected = mu_k * normal_N if slipped else trial_N
        np.testing.assert_allclose(f_t, [0.0, -expected, 0.0], rtol=0, atol=1e-9)


@pytest.mark.parametrize(
    ("gap_m", "speed_m_s", "horizon_s", "near"),
    [
        (-0.005, 0.0, 0.0, True),  # in
        (0.09, 0.0, 0.0, True),  # within the two clearances
        (0.15, 0.0, 0.01, False),  # 15 cm apart, still
        (0.15, 10.0, 0.01, True),  # 10 cm covered in the horizon (twice it: 20 cm)
        (0.15, 3.0, 0.01, True),  # 3 cm covered (6 cm)
        (0.15, 1.0, 0.01, False),  # 1 cm covered (2 cm)
        (0.15, 10.0, 0.0, False),  # no horizon
    ],
)
def test_a_pair_is_near_when_its_pieces_can_meet_within_the_horizon(
    load_body, gap_m, speed_m_s, horizon_s, near
):
    """`PiecePairs.near`: the robot's sphere and the ball, ``gap_m`` apart, the robot coming
    at ``speed_m_s``: near when their bounding spheres overlap, each grown by a clearance
    (5 cm) and twice the distance its points can cover in ``horizon_s`` (what lets a period
    skip the pairs)."""
    system, q, _ = _touching(load_body)
    (pairs,) = system.moving.moving.sets
    q[0] -= gap_m + 0.005  # _touching's robot is 5 mm into the ball
    v = np.zeros(6)
    v[0] = speed_m_s  # towards the ball
    states = system.moving.initial_states()
    system.moving._kinematics(q, v, states)
    data = system.moving.moving._datas(system.moving.uvms_data, system.moving.datas)
    assert pairs.pairs.near(data(pairs.a), data(pairs.b), horizon_s) is near


def test_a_force_on_a_body_fixed_to_the_world_moves_no_joint():
    """A fixture's root link hangs on joint 0 (the world): a contact force on it is taken by
    the world (zero generalized force; Pinocchio's Jacobian of joint 0 is not asked for),
    while a force on a moving body beside it still counts."""
    from uvms_pin.physics.world.pairs import joint_forces

    model = pin.Model()
    hinge = model.addJoint(0, pin.JointModelRY(), pin.SE3.Identity(), "hinge")
    model.appendBodyToJoint(hinge, pin.Inertia.FromSphere(1.0, 0.1), pin.SE3.Identity())
    data = model.createData()
    q = np.zeros(1)
    pin.forwardKinematics(model, data, q)
    force = np.array([[0.0, 0.0, 10.0]])
    on_world = joint_forces(model, data, q, [0], [[1.0, 0.0, 0.0]], force)
    assert np.array_equal(on_world, np.zeros(1))
    # 10 N up at 1 m along x about y: -10 N m; the world's share adds nothing
    both = joint_forces(
        model, data, q, [0, hinge], [[1.0, 0, 0], [1.0, 0, 0]], np.vstack([force, force])
    )
    assert np.allclose(both, [-10.0])
    nothing = pin.Model()
    assert joint_forces(
        nothing, nothing.createData(), np.zeros(0), [0], [[0, 0, 0]], force
    ).shape == (0,)


class _BoxAndBar:
    """A box robot (10 cm) and a free bar (a cylinder 1 m long, 5 cm across, at z = -5 m),
    and the core's search of their pairs (`PairSearch`), kept from call to call."""

    def __init__(self, load_body):
        self.box = _body(load_body, '<box size="0.1 0.1 0.1"/>')
        bar = free_object(
            "bar", "cylinder", {"radius_m": 0.025, "length_m": 1.0}, ([0.0, 0.0, -5.0], [0, 0, 0]),
            density_kg_m3=1200.0, water_density_kg_m3=RHO,
        )  # fmt: skip
        self.system = System(Plant(self.box, world=World(self.box, [], ContactLaw(), [bar])))
        (self.pairs,) = self.system.moving.moving.sets
        self.search = PairSearch(self.pairs.pairs, core_module())
        self.states = self.system.moving.initial_states()

    def compare(self, q: np.ndarray, v: np.ndarray) -> int:
        """The core's touching pairs, forces and points at (q, v) against the reference's
        (to 1e-12); how many pairs touch."""
        moving, pairs = self.system.moving, self.pairs
        moving._kinematics(q, v, self.states)
        data = moving.moving._datas(moving.uvms_data, moving.datas)
        python = pairs.pairs.forces(data(pairs.a), data(pairs.b), pairs.memory)
        core = self.search(data(pairs.a), data(pairs.b), pairs.memory)
        assert np.array_equal(core.pair, python.pair), q
        np.testing.assert_allclose(core.force_world_N, python.force_world_N, rtol=0, atol=1e-12)
        np.testing.assert_allclose(
            core.touch.point_world_m, python.touch.point_world_m, rtol=0, atol=1e-12
        )
        return len(python.pair)


def test_the_core_finds_a_bars_contacts_as_the_reference_does(load_body):
    """A box robot (10 cm) posed all about a free bar (a cylinder 1 m long, 5 cm across):
    beside it, past its ends, into it. The core's search (`PairSearch`, its pieces' spheres
    tested against the solid cylinder before coal's GJK) finds the reference's touching
    pairs, points and forces (`PiecePairs.forces`) at every pose, to 1e-12."""
    scene = _BoxAndBar(load_body)
    rng = np.random.default_rng(38)
    touching = 0
    for _ in range(300):
        q = scene.box.neutral_configuration()
        # the box's centre 0 to 15 cm from the bar's axis, up to 10 cm past its ends
        angle, radial, along = (
            rng.uniform(0, 2 * np.pi),
            rng.uniform(0.0, 0.15),
            rng.uniform(-0.6, 0.6),
        )
        q[:3] = [radial * np.cos(angle), radial * np.sin(angle), -5.0 + along]
        q[3:7] = pin.Quaternion(pin.exp3(rng.normal(size=3))).coeffs()
        v = rng.normal(scale=0.1, size=6)
        touching += scene.compare(q, v)
    assert 30 < touching < 270  # both kinds of pose


def test_the_core_skips_coal_only_for_a_pair_still_apart(load_body):
    """A tilted box robot (10 cm) brought to a free bar's side from 2 mm away, into it (0.2
    mm) and back, the gap crossing the core's cut (a pair coal found apart is not searched
    again while GJK's last separating direction still leaves a gap over 1e-5 m between the
    two shapes: `NarrowPhase`) at 0.1 um and below: at every pose the core's search, kept
    from pose to pose, finds the reference's touching pairs, points and forces to 1e-12."""
    scene = _BoxAndBar(load_body)
    tilt = pin.exp3(np.array([0.01, 0.02, 0.0]))  # an edge of the box towards the bar
    reach = 0.05 * np.abs(tilt[0]).sum()  # of the box from its centre towards the bar
    # the gap [m]: 2 mm down to 0.1 um, 0.2 mm in, and back
    closing = np.concatenate([np.geomspace(2e-3, 1e-7, 80), -np.geomspace(1e-7, 2e-4, 40)])
    gaps = np.concatenate([closing, closing[::-1]])
    touching = 0
    for k, gap in enumerate(gaps):
        q = scene.box.neutral_configuration()
        q[:3] = [0.025 + reach + gap, 0.0, -5.0 + 0.01 * np.cos(k)]
        q[3:7] = pin.Quaternion(tilt).coeffs()
        touching += scene.compare(q, np.full(6, 0.01))
    assert 0 < touching < len(gaps)  # both sides of the contact


def test_two_pieces_touching_one_object_at_once_get_mirrored_pairs(load_body):
    """A robot of two spheres (r = 0.1 m, 16 cm apart along y) posed symmetrically about
    y = 0, both 9 mm into a free ball's side (r = 0.2 m) at once: two touching pairs of
    one set, mirror images of each other (y negated) in their points and forces, each
    force pushing the robot away from the ball; the core finds the reference's."""
    second = '</geometry></collision><collision><origin xyz="0 0.16 0"/><geometry>'
    twins = _body(load_body, f'<sphere radius="0.1"/>{second}<sphere radius="0.1"/>')
    ball = free_object(
        "ball", "sphere", {"radius_m": 0.2}, ([0.0, 0.0, -5.0], [0, 0, 0]),
        density_kg_m3=RHO, water_density_kg_m3=RHO,
    )  # fmt: skip
    system = System(Plant(twins, world=World(twins, [], ContactLaw(), [ball])))
    (pairs,) = system.moving.moving.sets
    offsets = np.array([p.placement_in_joint.translation for p in pairs.pairs.pieces_a])
    assert np.ptp(offsets[:, 1]) == pytest.approx(0.16)
    q = twins.neutral_configuration()
    # the spheres at y = +-0.08 m: centres 0.2912 m from the ball's, 8.8 mm deep each
    q[:3] = [-0.28 - offsets[:, 0].mean(), -offsets[:, 1].mean(), -5.0 - offsets[:, 2].mean()]
    states = system.moving.initial_states()
    system.moving._kinematics(q, np.zeros(6), states)
    data = system.moving.moving._datas(system.moving.uvms_data, system.moving.datas)
    python = pairs.pairs.forces(data(pairs.a), data(pairs.b), pairs.memory)
    assert len(python) == 2
    points, forces = python.touch.point_world_m, python.force_world_N
    low, high = np.argsort(points[:, 1])
    mirror = np.array([1.0, -1.0, 1.0])
    np.testing.assert_allclose(points[low] * mirror, points[high], rtol=0, atol=1e-9)
    np.testing.assert_allclose(forces[low] * mirror, forces[high], rtol=1e-9, atol=1e-9)
    assert np.all(forces[:, 0] < 0.0)
    core = PairSearch(pairs.pairs, core_module())(data(pairs.a), data(pairs.b), pairs.memory)
    assert np.array_equal(core.pair, python.pair)
    np.testing.assert_allclose(core.force_world_N, forces, rtol=0, atol=1e-12)
