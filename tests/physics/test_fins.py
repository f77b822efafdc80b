"""The fins' lift and drag in the dynamics (`uvms_pin.physics.fins`): the generalized force
is the fins' wrench through their joints' Jacobians (its power is the wrench's), a fin
moving with the water feels nothing, a fin above the free surface nothing either; the
compiled plant's fins (src/uvms_core/fins.hpp) agree with the reference, and a run with
fins is compiled."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from fin_helpers import import_lrauv

import uvms_pin as up
from uvms_pin.errors import ParameterError
from uvms_pin.flow import UniformCurrent
from uvms_pin.hydro.lift_drag import lift_drag_wrench
from uvms_pin.physics.fins import fin_generalized_force, fin_wrenches_world, wet_fraction
from uvms_pin.sim.plant import Plant


@pytest.fixture(scope="module")
def lrauv(tmp_path_factory):
    folder = tmp_path_factory.mktemp("lrauv")
    import_lrauv(folder)
    return up.load_uvms(folder / "lrauv.urdf", water_density_kg_m3=1000.0)


def _tau(uvms, data, q, v, water=None):
    return fin_generalized_force(uvms, data, q, fin_wrenches_world(uvms, data, q, v, water))


def _state(uvms, rng):
    q = pin.randomConfiguration(uvms.model, -np.ones(uvms.nq), np.ones(uvms.nq))
    q[3:7] = pin.Quaternion(pin.exp3(rng.normal(size=3))).coeffs()
    v = rng.normal(size=uvms.nv) * np.r_[1.0, 1.0, 1.0, 0.3, 0.3, 0.3, 1.0, 1.0]
    return q, v


def test_the_model_has_the_tutorials_two_fins(lrauv):
    fins = {f.name: f for f in lrauv.fins}  # in the URDF's link order
    assert sorted(fins) == ["horizontal_fins", "vertical_fins"]
    vertical = fins["vertical_fins"].params
    assert (vertical.cla, vertical.area_m2, vertical.fluid_density_kg_m3) == (4.13, 0.0244, 1000.0)
    assert (vertical.cla_stall, vertical.cda, vertical.cda_stall) == (-1.1, 0.2, 0.03)
    assert vertical.alpha_stall_rad == 0.17
    np.testing.assert_array_equal(vertical.forward, [-1.0, 0.0, 0.0])
    np.testing.assert_array_equal(vertical.upward, [0.0, 1.0, 0.0])
    assert lrauv.model.names[fins["vertical_fins"].joint_id] == "vertical_fins_joint"


def test_the_generalized_force_delivers_the_wrenchs_power_and_never_gains_energy(lrauv):
    """tau . v = sum F . v_c + M . omega (the Jacobian maps the wrench right), and with
    c_Ma = 0 it is <= 0: the fins take energy from the motion, never give it."""
    rng = np.random.default_rng(7)
    data = lrauv.model.createData()
    active = 0
    for _ in range(60):
        q, v = _state(lrauv, rng)
        tau = _tau(lrauv, data, q, v)
        power = 0.0
        for fin, (centre, force, moment) in zip(
            lrauv.fins, fin_wrenches_world(lrauv, data, q, v), strict=True
        ):
            motion = data.oMi[fin.joint_id].act(data.v[fin.joint_id])
            power += force @ (motion.linear + np.cross(motion.angular, centre))
            power += moment @ motion.angular
            active += bool(np.any(force))
        assert tau @ v == pytest.approx(power, rel=1e-10, abs=1e-12)
        assert tau @ v <= 1e-12
    assert active > 20  # most states have a fin in the flow


def test_a_fin_moving_with_the_water_feels_nothing_and_the_water_counts(lrauv):
    rng = np.random.default_rng(3)
    data = lrauv.model.createData()
    q = lrauv.neutral_configuration()
    q[:3] = rng.normal(size=3)
    velocity = np.array([-1.2, 0.1, 0.05])
    v = np.zeros(lrauv.nv)
    v[:3] = velocity  # at level attitude the body velocity is the world velocity
    moving = _tau(lrauv, data, q, v)
    assert np.any(moving)
    carried = _tau(lrauv, data, q, v, UniformCurrent(velocity))
    np.testing.assert_array_equal(carried, np.zeros(lrauv.nv))
    still_body = _tau(lrauv, data, q, np.zeros(lrauv.nv), UniformCurrent(-velocity))
    np.testing.assert_allclose(still_body, moving, rtol=1e-12, atol=1e-14)


def test_the_plant_adds_them_and_the_core_agrees_with_the_reference(lrauv):
    """The plant's acceleration is forward_dynamics with the fins' generalized force; the
    compiled plant (src/uvms_core/fins.hpp) gives the Python reference's to 1e-10 in random
    states, in still water, in a current and across the free surface; the force alone too;
    derivatives are refused by name on both."""
    from uvms_pin.physics.compiled.extension import core_module
    from uvms_pin.physics.compiled.fins import lift_drag_to_core

    rng = np.random.default_rng(5)
    tau = np.zeros(lrauv.nv)
    q, v = _state(lrauv, rng)
    reference = Plant(lrauv, backend="python", free_surface=False)
    extra = _tau(lrauv, lrauv.model.createData(), q, v)
    np.testing.assert_allclose(
        reference.acceleration(0.0, q, v, tau),
        up.forward_dynamics(lrauv, q, v, tau, tau_ext=extra, backend="python"),
        rtol=1e-12,
        atol=1e-12,
    )
    assert np.any(extra)
    for current, surface in (([0.0] * 3, False), ([0.3, -0.2, 0.1], False), ([0.0] * 3, True)):
        water = {"current_world_m_s": np.array(current), "free_surface": surface}
        python = Plant(lrauv, backend="python", **water)
        core = Plant(lrauv, **water)
        assert core.compiled is not None
        for _ in range(20):
            q, v = _state(lrauv, rng)
            if surface:  # the fins' centres near the surface: some wet, some not
                q[2] = rng.uniform(-0.3, 0.3)
            np.testing.assert_allclose(
                core.acceleration(0.0, q, v, tau),
                python.acceleration(0.0, q, v, tau),
                rtol=1e-10,
                atol=1e-10,
            )
    core = core_module()
    for fin in lrauv.fins:
        for _ in range(50):
            rotation = pin.exp3(rng.normal(size=3))
            velocity, control = rng.normal(size=3), rng.normal(scale=0.2)
            force, moment = core.lift_drag_wrench(
                lift_drag_to_core(fin.params, core), rotation, velocity, control
            )
            expected = lift_drag_wrench(fin.params, rotation, velocity, control)
            np.testing.assert_allclose(force, expected[0], rtol=1e-12, atol=1e-12)
            np.testing.assert_allclose(moment, expected[1], rtol=1e-12, atol=1e-12)
    with pytest.raises(ParameterError, match="fins' lift and drag"):
        reference.acceleration_derivatives(0.0, q, v, tau)
    with pytest.raises(ParameterError, match="fins"):
        Plant(lrauv).acceleration_derivatives(0.0, q, v, tau)


def test_a_run_with_fins_is_compiled_and_agrees_with_the_python_loop(tmp_path):
    import_lrauv(tmp_path)
    scenario = tmp_path / "run.toml"
    scenario.write_text(
        '[scenario]\nmodel = "lrauv.urdf"\nduration_s = 0.5\n\n[water]\ndensity_kg_m3 = 1000.0\n\n'
        "[initial]\nposition_world_m = [0.0, 0.0, -5.0]\n"
        "velocity = [-1.0, 0.0, 0.0, 0.0, 0.0, 0.2, 0.0, 0.0]\n\n"
        '[controller]\ntype = "none"\n'
    )
    compiled = up.simulate(up.load_scenario(scenario), progress=False)
    assert compiled.metadata["closed_loop"]["path"] == "compiled"
    python = up.simulate(up.load_scenario(scenario), progress=False, compiled_loop=False)
    assert python.metadata["closed_loop"]["path"] == "python"
    np.testing.assert_allclose(compiled.q, python.q, atol=1e-9)
    # the fins turned the motion: a run without them goes elsewhere
    assert np.max(np.abs(compiled.v[-1] - compiled.v[0])) > 1e-3


def test_a_fin_above_the_free_surface_gives_nothing_and_one_across_it_a_share(lrauv):
    """With a free surface a fin's wrench is scaled by its wet fraction: whole with its centre
    of pressure sqrt(A)/2 below the surface or deeper, nothing as far above it, half at it."""
    data = lrauv.model.createData()
    k = [f.name for f in lrauv.fins].index("vertical_fins")  # in the flow of v below
    fin = lrauv.fins[k]
    size = np.sqrt(fin.params.area_m2)
    v = np.zeros(lrauv.nv)
    v[:3] = [-1.2, 0.1, 0.05]

    def wrench_at(depth_m: float):
        q = lrauv.neutral_configuration()
        pin.forwardKinematics(lrauv.model, data, q)
        centre = (data.oMi[fin.joint_id] * fin.placement_in_joint).act(fin.params.cp_m)
        q[2] += -depth_m - centre[2]  # the fin's centre of pressure at z = -depth
        wet = fin_wrenches_world(lrauv, data, q, v, free_surface=True)[k]
        whole = fin_wrenches_world(lrauv, data, q, v)[k]
        return wet, whole

    deep, whole = wrench_at(size)
    np.testing.assert_array_equal(deep[1], whole[1])
    assert np.any(whole[1])
    dry, _ = wrench_at(-size)
    np.testing.assert_array_equal(dry[1], np.zeros(3))
    half, whole = wrench_at(0.0)
    np.testing.assert_allclose(half[1], 0.5 * whole[1], rtol=1e-12)
    assert wet_fraction(np.array([0.0, 0.0, 0.25 * size]), fin.params.area_m2, None, 0.0) == 0.25


def test_the_mujoco_twin_of_a_model_with_fins_says_it_leaves_them_out(lrauv):
    from pathlib import Path

    from uvms_pin.apps.export.mjcf import uvms_to_mjcf
    from uvms_pin.errors import ModelWarning

    with pytest.warns(ModelWarning, match="'horizontal_fins', 'vertical_fins' have no MuJoCo"):
        uvms_to_mjcf(lrauv, Path(lrauv.source).read_text(), base_dir=Path(lrauv.source).parent)


class _SwellStub:
    """A free surface eta(t, x) = 0.2 sin(x + t) [m] (only `surface_elevation` is read)."""

    def surface_elevation(self, time_s, xy_world):
        xy = np.asarray(xy_world, dtype=float).reshape(-1, 2)
        return 0.2 * np.sin(xy[:, 0] + time_s)


@pytest.mark.parametrize("depth_m", [-0.2, -0.05, 0.0, 0.03, 0.1, 0.2])
def test_the_wet_fraction_follows_the_local_surface_not_the_level(depth_m):
    """w depends only on the centre of pressure's height above the free surface where it
    is, c_z - eta(t, c_xy): a fin at a height d above a swell's crest, trough or slope is
    as wet as one at d above the level surface z = 0."""
    area = 0.04  # L = 0.2 m
    level = wet_fraction(np.array([0.0, 0.0, depth_m]), area, None, 0.0)
    for x, t in ((0.0, 0.0), (0.3, 1.2), (1.0, 0.5708), (-1.0, 0.0)):
        eta = 0.2 * np.sin(x + t)
        centre = np.array([x, 0.4, eta + depth_m])
        assert wet_fraction(centre, area, _SwellStub(), t) == pytest.approx(level, abs=1e-12)
