"""Overlaps at the start (`uvms_pin.physics.world.overlap`): a free object placed inside the
vehicle, the seabed or another free object is refused naming both bodies and the depth, a
resting contact is accepted, and ``initial_overlap = "separate"`` moves the object out so
that the run starts without a kick."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import RHO, ROOT, run

from uvms_pin.errors import InitialOverlapError, ParameterError
from uvms_pin.physics.world.contact_law import ContactLaw
from uvms_pin.physics.world.free_object import free_object
from uvms_pin.physics.world.objects import plane
from uvms_pin.physics.world.overlap import OVERLAP_TOLERANCE_M, tolerance_m
from uvms_pin.physics.world.world import World
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System

FLOOR_Z = -10.0
RADIUS = 0.1


def _ball(name: str, center, density: float = 2600.0):
    return free_object(
        name, "sphere", {"radius_m": RADIUS}, (np.asarray(center, float), [0, 0, 0]),
        density_kg_m3=density, water_density_kg_m3=RHO,
    )  # fmt: skip


def _system(uvms, free, objects=(), overlap="refuse") -> System:
    world = World(uvms, list(objects), ContactLaw(), free, initial_overlap=overlap)
    return System(Plant(uvms, world=world, free_surface=False))


def _vehicle_center(uvms) -> tuple[np.ndarray, np.ndarray]:
    """(the neutral configuration raised to 5 m depth, the vehicle's hull centre there)."""
    q = uvms.neutral_configuration()
    q[2] = -5.0
    data = uvms.model.createData()
    pin.forwardKinematics(uvms.model, data, q)
    world = World(uvms, [])
    hull = next(p for p in world.pieces if p.joint_id == 1)
    return q, (data.oMi[1] * hull.placement_in_joint).translation


def test_a_sphere_inside_the_vehicle_is_refused_naming_both_and_the_depth(reference_uvms):
    q, center = _vehicle_center(reference_uvms)
    system = _system(reference_uvms, [_ball("ball", center)])
    with pytest.raises(InitialOverlapError) as caught:
        system.initial_state(q, np.zeros(reference_uvms.nv))
    error = caught.value
    assert error.second == "ball" and error.first in World(reference_uvms, []).body_names
    assert error.depth_m > 0.1  # the ball's centre at the hull's: deeper than its radius
    message = str(error)
    assert "'ball'" in message and f"'{error.first}'" in message
    assert f"{error.depth_m * 1e3:.3g} mm" in message and 'initial_overlap = "separate"' in message
    assert isinstance(error, ParameterError)  # bad input: the command line exits with 2


def test_a_sphere_inside_the_seabed_is_refused(load_body):
    pusher = _pusher(load_body)
    floor = plane("seabed", [0, 0, FLOOR_Z], [0, 0, 1], 0.6, 0.5)
    ball = _ball("ball", [0.0, 0.0, FLOOR_Z + RADIUS - 0.03])  # 3 cm into the seabed
    system = _system(pusher, [ball], [floor])
    with pytest.raises(
        InitialOverlapError, match=r"'seabed' and 'ball' overlap by 30 mm"
    ) as caught:
        system.initial_state(_far(pusher), np.zeros(6))
    # its tolerance: twice the depth at which one point carries its net weight (6.5 mm)
    assert "more than the 6.5 mm tolerance" in str(caught.value)
    assert 2 * _net_weight(ball) / 2e4 == pytest.approx(6.47e-3, abs=5e-6)


def test_two_free_objects_overlapping_are_refused(load_body):
    pusher = _pusher(load_body)
    first = _ball("first", [0.0, 0.0, -5.0])
    second = _ball("second", [0.15, 0.0, -5.0])  # 5 cm into the first
    system = _system(pusher, [first, second])
    with pytest.raises(InitialOverlapError) as caught:
        system.initial_state(_far(pusher), np.zeros(6))
    assert (caught.value.first, caught.value.second) == ("first", "second")
    assert caught.value.depth_m == pytest.approx(0.05, abs=1e-9)


def test_resting_contacts_are_accepted(load_body):
    """Touching (depth 0), a dense sphere at its resting depth (W - B) / k (3.2 mm) and a
    dense box at its resting depth (W - B) / (4 k) (7.6 mm) on the seabed: within their
    tolerances (2 (W - B) / k), the state is the scenario's."""
    pusher = _pusher(load_body)
    law = ContactLaw()
    floor = plane("seabed", [0, 0, FLOOR_Z], [0, 0, 1], 0.6, 0.5)
    probe = _ball("ball", [0.0, 0.0, 0.0])
    sunk = _net_weight(probe) / law.stiffness_N_m
    ball = _ball("ball", [0.0, 0.0, FLOOR_Z + RADIUS - sunk])
    size = [0.25, 0.5, 0.25]
    box = free_object(
        "box", "box", {"size_m": size}, ([1.0, 0.0, 0.0], [0, 0, 0]),
        density_kg_m3=3000.0, water_density_kg_m3=RHO,
    )  # fmt: skip
    resting = _net_weight(box) / (4 * law.stiffness_N_m)
    assert OVERLAP_TOLERANCE_M < sunk < resting < tolerance_m(box, law)
    box = free_object(
        "box", "box", {"size_m": size}, ([1.0, 0.0, FLOOR_Z + 0.125 - resting], [0, 0, 0]),
        density_kg_m3=3000.0, water_density_kg_m3=RHO,
    )  # fmt: skip
    touching = _ball("touching", [0.0, 0.2, FLOOR_Z + RADIUS - sunk])  # touches the ball
    system = _system(pusher, [ball, box, touching], [floor])
    state = system.initial_state(_far(pusher), np.zeros(6))
    np.testing.assert_array_equal(state.q[7:14], ball.q0)
    np.testing.assert_array_equal(state.q[14:21], box.q0)
    np.testing.assert_array_equal(state.q[21:28], touching.q0)
    assert system.separations == []


def test_separate_moves_the_sphere_out_of_the_vehicle_and_the_run_has_no_kick(reference_uvms):
    """The ball starts with its centre 6 cm above the hull's (17 cm deep in it); separated,
    it starts on the hull's top and settles there: the largest contact force of the first
    half second is of the order of its net weight (65 N), not the kick the overlap gave
    (1.7 kN with the overlapping state run as given)."""
    q, center = _vehicle_center(reference_uvms)
    ball = _ball("ball", center + np.array([0.0, 0.0, 0.06]))
    uvms = reference_uvms
    system = _system(uvms, [ball], overlap="separate")
    state = system.initial_state(q, np.zeros(uvms.nv))
    (move,) = system.separations
    assert move.second == "ball" and move.depth_m > 0.1
    assert move.direction_world[2] > 0.99  # out through the hull's top
    moved = state.q[uvms.nq : uvms.nq + 3] - ball.q0[:3]
    np.testing.assert_allclose(moved, move.depth_m * move.direction_world, atol=1e-12)
    record = system.log.record()["world"]["initial_overlap"]
    assert record["mode"] == "separate"
    assert record["tolerance_m"] == {"ball": pytest.approx(2 * _net_weight(ball) / 2e4)}
    assert record["moved"][0]["object"] == "ball"
    assert record["moved"][0]["depth_m"] == pytest.approx(move.depth_m)
    # nothing deeper than the tolerance is left
    assert system.moving.apart(q, [(state.q[uvms.nq :], state.v[uvms.nv :])])[1] == []
    system.start(state)
    q_sys, v_sys, peak = state.q, state.v, 0.0
    tau = np.zeros(uvms.nv)
    for k in range(250):  # 0.5 s
        q_sys, v_sys = system.advance(RK4(5e-4), k * 2e-3, q_sys, v_sys, tau, (k + 1) * 2e-3)
        (q_r, v_r), *objects = system.layout.split(q_sys, v_sys)
        sets, _ = system.moving.found(q_r, v_r, objects)
        peak = max([peak, *(float(np.abs(s.normal_N).max()) for s in sets if len(s))])
    weight = _net_weight(ball)
    assert 0.5 * weight < peak < 2.0 * weight  # it rests on the hull, landing softly


def test_an_unknown_mode_is_refused(load_body):
    pusher = _pusher(load_body)
    with pytest.raises(ParameterError, match="initial_overlap"):
        World(pusher, [], ContactLaw(), [], initial_overlap="push")


def test_the_command_line_refuses_an_overlap_with_status_2_and_one_line(tmp_path):
    out = tmp_path / "run"
    result = run(
        "run", str(ROOT / "scenarios" / "push_object.toml"), "--quiet", "--out", str(out),
        "--set", "world.objects[1].position_world_m=[0.8, -0.11, -9.95]",
    )  # fmt: skip
    assert result.returncode == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert lines == [
        "uvms-pin: error: 'seabed' and 'box' overlap by 75 mm at the start (more than the 2.3 "
        'mm tolerance): place them apart, or set [world] initial_overlap = "separate" to move '
        "the free object out along the contact normal before the run"
    ]
    assert "Traceback" not in result.stderr
    assert not out.exists()


def _pusher(load_body):
    from conftest import body_urdf, hydro_xml

    urdf = body_urdf(
        mass=4.0, inertia=(0.016,) * 3, hydro=hydro_xml(4.0 / RHO),
        collision=f'<sphere radius="{RADIUS}"/>',
    )  # fmt: skip
    return load_body(urdf)


def _net_weight(obj) -> float:
    """W - B [N]."""
    return -obj.uvms.net_buoyancy_N


def _far(pusher) -> np.ndarray:
    q = pusher.neutral_configuration()
    q[:3] = [20.0, 0.0, -5.0]
    return q


def test_a_scenario_s_separate_moves_the_box_out_of_the_seabed_and_says_so():
    """``[world] initial_overlap = "separate"`` read from the scenario: the box 75 mm in the
    seabed starts on it, and the run's metadata lists the move."""
    from uvms_pin.scenario.load import load_scenario

    scenario = load_scenario(
        ROOT / "scenarios" / "push_object.toml",
        {
            "world.objects[1].position_world_m": [0.8, -0.11, -9.95],
            "world.initial_overlap": "separate",
        },
    )
    assert scenario.plant.world.initial_overlap == "separate"
    system = System(scenario.plant)
    state = system.initial_state(scenario.q0, scenario.v0)
    nq = scenario.plant.uvms.nq
    assert state.q[nq + 2] == pytest.approx(-10.0 + 0.125, abs=1e-9)  # on the seabed
    (moved,) = system.log.record()["world"]["initial_overlap"]["moved"]
    assert moved["object"] == "box" and moved["bodies"] == ["seabed", "box"]
    assert moved["depth_m"] == pytest.approx(0.075, abs=1e-9)
    assert moved["moved_world_m"] == pytest.approx([0.0, 0.0, 0.075], abs=1e-9)


def test_the_robot_started_inside_a_fixed_box_is_refused_naming_both(tmp_path):
    """The robot's own start in a fixed object (a rock at its arm): it never moves, so the
    run is refused (status 2, one line) in either mode; before, the compressed contact flung
    the passive robot out, +6.5 J from nothing in 0.04 s."""
    box = '{type="box", name="rock", size_m=[0.3, 0.3, 0.3], position_world_m=[0.75, 0.0, -2.1]}'
    for mode in ("refuse", "separate"):
        out = tmp_path / mode
        result = run(
            "run", str(ROOT / "scenarios" / "passive_still_water.toml"), "--quiet",
            "--out", str(out), "--set", f"world={{objects=[{box}], initial_overlap=\"{mode}\"}}",
        )  # fmt: skip
        assert result.returncode == 2, result.stderr
        (line,) = result.stderr.strip().splitlines()
        assert line.startswith("uvms-pin: error: 'arm_link") and "and 'rock' overlap by 7" in line
        assert "the robot is never moved" in line and "Traceback" not in result.stderr
        assert not out.exists()


def test_the_robot_under_the_seabed_is_refused_and_one_clear_of_it_is_not():
    """A run (`simulate`) with a seabed 0.5 m over its pieces' lowest bound is refused,
    naming the seabed; the same seabed 1 mm under every piece's bounding sphere runs."""
    from uvms_pin.scenario.load import load_scenario
    from uvms_pin.sim.run import simulate

    scenario = load_scenario(ROOT / "scenarios" / "passive_still_water.toml")
    uvms, q = scenario.plant.uvms, scenario.q0
    data = uvms.model.createData()
    pin.forwardKinematics(uvms.model, data, q)
    lowest = min(
        (data.oMi[p.joint_id] * p.placement_in_joint).translation[2] - p.bound_radius_m
        for p in World(uvms, []).pieces
    )

    def run(seabed_z: float):
        seabed = {"type": "plane", "name": "seabed", "point_world_m": [0.0, 0.0, seabed_z]}
        overrides = {"world": {"objects": [seabed]}, "scenario.duration_s": 0.04}
        return simulate(load_scenario(ROOT / "scenarios" / "passive_still_water.toml", overrides))

    assert run(lowest - 1e-3).metadata["status"] == "ok"
    with pytest.raises(InitialOverlapError, match="and 'seabed' overlap by") as caught:
        run(lowest + 0.5)
    assert caught.value.second == "seabed" and caught.value.depth_m > 0.01
