"""Joint-drive friction: dissipative, its limits, and the compiled plant = the reference."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import REFERENCE_URDF

from uvms_pin.errors import ParameterError
from uvms_pin.model.urdf.load import load_uvms
from uvms_pin.physics.joint_friction import JointFriction
from uvms_pin.sim.plant import Plant

FRICTION = JointFriction(
    np.array([0.5, 0.8, 0.3, 0.1]),
    np.array([0.4, 0.2, 0.3, 0.05]),
    np.array([0.01, 0.02, 0.01, 0.05]),
)


def test_power_is_never_positive_and_the_limits_hold():
    rng = np.random.default_rng(0)
    for v in rng.normal(scale=0.5, size=(200, 4)):
        assert FRICTION.torque_Nm(v) @ v <= 0.0
    # far above s: viscous plus the full Coulomb torque; at rest: nothing
    v = np.full(4, 10.0)
    np.testing.assert_allclose(
        FRICTION.torque_Nm(v), -(FRICTION.viscous_Nms * 10 + FRICTION.coulomb_Nm), rtol=1e-12
    )
    assert not np.any(FRICTION.torque_Nm(np.zeros(4)))
    # odd in the velocity
    np.testing.assert_array_equal(FRICTION.torque_Nm(-v), -FRICTION.torque_Nm(v))


@pytest.fixture(scope="module")
def uvms():
    return load_uvms(REFERENCE_URDF)


def test_compiled_plant_equals_the_reference(uvms):
    rng = np.random.default_rng(1)
    core = Plant(uvms, joint_friction=FRICTION, free_surface=False)
    python = Plant(uvms, joint_friction=FRICTION, free_surface=False, backend="python")
    for _ in range(5):
        q = uvms.neutral_configuration()
        q[:3] = [0.0, 0.0, -3.0]
        q[7:] = rng.uniform(-0.5, 0.5, size=4)
        v = rng.normal(scale=0.3, size=uvms.nv)
        tau = rng.normal(size=uvms.nv)
        a_core = core.acceleration(0.0, q, v, tau)
        a_python = python.acceleration(0.0, q, v, tau)
        np.testing.assert_allclose(
            a_core, a_python, rtol=1e-12, atol=1e-12 * np.max(np.abs(a_python))
        )


def test_friction_is_a_generalized_force_on_the_joints(uvms):
    """M a_f - M a_0 = [0; tau_f(v)]: the friction enters as joint torque, nothing else."""
    from uvms_pin.physics.dynamics import mass_matrix

    q = uvms.neutral_configuration()
    q[:3] = [0.0, 0.0, -3.0]
    v = np.linspace(-0.3, 0.4, uvms.nv)
    tau = np.zeros(uvms.nv)
    with_friction = Plant(uvms, joint_friction=FRICTION, free_surface=False).acceleration(
        0.0, q, v, tau
    )
    without = Plant(uvms, free_surface=False).acceleration(0.0, q, v, tau)
    generalized = mass_matrix(uvms, q) @ (with_friction - without)
    np.testing.assert_allclose(generalized[:6], 0.0, atol=1e-10)
    np.testing.assert_allclose(generalized[6:], FRICTION.torque_Nm(v[6:]), rtol=1e-9)


@pytest.mark.parametrize(
    ("b", "c", "s", "match"),
    [
        ([-1.0], [0.0], [0.01], "viscous_Nms"),
        ([0.0], [-1.0], [0.01], "coulomb_Nm"),
        ([0.0], [1.0], [0.0], "velocity scale"),
    ],
)
def test_bad_friction_is_refused(b, c, s, match):
    with pytest.raises(ParameterError, match=match):
        JointFriction(np.array(b), np.array(c), np.array(s))


def test_friction_for_the_wrong_number_of_joints_is_refused(uvms):
    with pytest.raises(ParameterError, match="joint friction for 1 joints"):
        Plant(uvms, joint_friction=JointFriction(np.ones(1), np.ones(1), np.ones(1)))


def test_the_urdfs_dynamics_friction_is_used_only_when_asked(tmp_path):
    from conftest import ROOT

    from uvms_pin.scenario.load import load_scenario

    text = REFERENCE_URDF.read_text()
    marked = text.replace("</joint>", '<dynamics damping="0.5" friction="0.2"/></joint>')
    (tmp_path / "model.urdf").write_text(marked)
    scenario = (ROOT / "scenarios" / "passive_still_water.toml").read_text()
    scenario = scenario.replace('model = "uvms_lbv150"', 'model = "model.urdf"')
    (tmp_path / "run.toml").write_text(scenario)
    assert load_scenario(tmp_path / "run.toml").plant.joint_friction is None
    plant = load_scenario(tmp_path / "run.toml", {"joints.use_model_friction": True}).plant
    np.testing.assert_array_equal(plant.joint_friction.viscous_Nms, [0.5] * 4)
    # with a control period the Coulomb part is a constraint (true stiction) by default
    np.testing.assert_array_equal(plant.joint_friction.coulomb_Nm, [0.0] * 4)
    np.testing.assert_array_equal(plant.joint_coulomb.coulomb_Nm, [0.2] * 4)
    smooth = {"joints.use_model_friction": True, "joints.coulomb": "smooth"}
    friction = load_scenario(tmp_path / "run.toml", smooth).plant.joint_friction
    np.testing.assert_array_equal(friction.coulomb_Nm, [0.2] * 4)
