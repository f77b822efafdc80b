"""A scenario on a UVMS with continuous arm joints, end to end: initial angles, the run on
both backends, the rollout's table and metrics (no joint limits for a continuous joint),
the baselines' posture term, ``info`` and the MJCF export."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT, continuous_joint_urdf

import uvms_pin as up
from uvms_pin.control.baselines.impedance import ImpedanceController
from uvms_pin.control.measurement import Measurement
from uvms_pin.errors import ScenarioError
from uvms_pin.model.summary import model_summary
from uvms_pin.results.metrics import joint_limit_metrics
from uvms_pin.results.rollout import Rollout
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

REALISTIC = ROOT / "scenarios" / "realistic_force_tracking.toml"


def _scenario(urdf, **overrides):
    return load_scenario(
        REALISTIC, {"scenario.model": str(urdf), "scenario.duration_s": 0.2, **overrides}
    )


def test_initial_angles_of_continuous_joints_are_any_angle(tmp_path):
    urdf = continuous_joint_urdf(tmp_path)
    scenario = _scenario(urdf, **{"initial.joint_positions_rad": [4.0, 1.0, -0.8, 0.2]})
    q0 = scenario.q0
    assert q0.shape == (15,)
    np.testing.assert_allclose(q0[7:9], [np.cos(4.0), np.sin(4.0)], rtol=0, atol=1e-15)
    # the joint count is one per joint, not per configuration entry
    with pytest.raises(ScenarioError, match=r"joint_positions_rad.: needs 4 numbers, got 8"):
        _scenario(urdf, **{"initial.joint_positions_rad": [1.0, 0.0] * 4})


def test_a_limited_joint_is_still_checked_beside_a_continuous_one(tmp_path):
    urdf = continuous_joint_urdf(tmp_path, ("arm_joint1",))
    # joint 1 at 3 rad: past the revolute original's +-1.6, fine once continuous
    scenario = _scenario(urdf, **{"initial.joint_positions_rad": [3.0, 1.0, -0.8, 0.2]})
    assert scenario.uvms.nq == 12
    with pytest.raises(ScenarioError, match=r"outside the joint limits for arm_joint2$"):
        _scenario(urdf, **{"initial.joint_positions_rad": [3.0, 2.5, -0.8, 0.2]})


@pytest.mark.parametrize("backend", ["core", "python"])
def test_the_paper_task_runs_on_continuous_joints(tmp_path, backend):
    """The PPC with its null-space pull holds the task; core and reference agree."""
    urdf = continuous_joint_urdf(tmp_path)
    rollout = simulate(_scenario(urdf, **{"integrator.backend": backend}), progress=False)
    assert rollout.status.ok and rollout.q.shape == (len(rollout), 15)
    cos, sin = rollout.q[:, 7::2], rollout.q[:, 8::2]
    np.testing.assert_allclose(np.hypot(cos, sin), 1.0, rtol=0, atol=1e-12)
    table = rollout.to_dataframe()
    assert "q.arm_joint1.cos" in table and "q.arm_joint4.sin" in table
    assert table.attrs["units"]["v.arm_joint1_rad_s"] == "rad/s"
    metrics = rollout.metrics()
    assert "joint_limit_excess_max_rad" not in metrics  # no joint has limits
    assert rollout.metadata["arm_joint_kinds"] == ["continuous"] * 4
    assert rollout.metadata["arm_position_lower_rad"] == [None] * 4


def test_backends_agree_on_a_continuous_run(tmp_path):
    urdf = continuous_joint_urdf(tmp_path, ("arm_joint1", "arm_joint3"))
    runs = [
        simulate(_scenario(urdf, **{"integrator.backend": b}), progress=False)
        for b in ("core", "python")
    ]
    scale = np.max(np.abs(runs[1].q))
    assert np.max(np.abs(runs[0].q - runs[1].q)) <= 1e-9 * scale


def test_backends_agree_on_a_continuous_run_through_the_free_surface(tmp_path):
    """At the waterline (the hull and the arm's links cut by the surface, their wet parts
    changing): the core's wet-state dynamics with (cos, sin) joint coordinates agree with
    the reference's."""
    urdf = continuous_joint_urdf(tmp_path, ("arm_joint1", "arm_joint3"))
    at_surface = {"initial.position_world_m": [0.0, 0.0, -0.05], "water.free_surface": True}
    runs = [
        simulate(_scenario(urdf, **{"integrator.backend": b, **at_surface}), progress=False)
        for b in ("core", "python")
    ]
    wet = runs[1].signals["wet_fraction"]
    assert np.any(wet < 1.0 - 1e-6) and np.ptp(wet, axis=0).max() > 0.0  # cut, and moving
    scale = np.max(np.abs(runs[1].q))
    assert np.max(np.abs(runs[0].q - runs[1].q)) <= 1e-9 * scale
    np.testing.assert_allclose(runs[0].signals["wet_fraction"], wet, rtol=0, atol=1e-9)


def test_joint_limit_metrics_skip_continuous_joints():
    """Joint 1 continuous at 3 rad, joint 2 revolute 0.5 rad past its upper limit."""
    n = 4
    q = np.zeros((n, 7 + 2 + 1))
    q[:, 6] = 1.0
    q[:, 7:9] = np.cos(3.0), np.sin(3.0)
    q[:, 9] = [0.0, 2.5, 2.5, 0.0]  # limits [-0.3, 2.0]
    rollout = Rollout.allocate(n, 10, 8, {})
    rollout.q[:] = q
    rollout.metadata.update(
        arm_joint_kinds=["continuous", "revolute"],
        arm_position_lower_rad=[None, -0.3],
        arm_position_upper_rad=[None, 2.0],
    )
    metrics = joint_limit_metrics(rollout)
    assert metrics["joint_limit_excess_max_rad"] == pytest.approx(0.5)
    assert metrics["joint_limit_excess_time_fraction"] == pytest.approx(0.5)
    # metadata that does not describe the columns: no metric rather than a wrong one
    rollout.metadata["arm_joint_kinds"] = ["revolute", "revolute"]
    assert joint_limit_metrics(rollout) == {}


def test_impedance_posture_is_the_revolute_models(tmp_path, reference_uvms):
    """The posture term pulls each joint by its angle error, as on the revolute model."""
    continuous = up.load_uvms(continuous_joint_urdf(tmp_path))
    angles0 = np.array([0.1, 1.0, -0.8, 0.2])
    angles1 = angles0 + np.array([0.3, -0.2, 0.1, 0.4])
    taus = []
    for uvms in (reference_uvms, continuous):
        controller = ImpedanceController(uvms.model, "ee", posture_stiffness_Nm_rad=2.0)
        base = uvms.neutral_configuration()[:7]
        for angles in (angles0, angles1):
            q = np.r_[base, uvms.arm_joints.configuration(angles)]
            tau = controller.compute(0.0, Measurement(0.0, q, np.zeros(10), np.zeros(6)))
        taus.append(tau)
    np.testing.assert_allclose(taus[1], taus[0], rtol=1e-12, atol=1e-12)


def test_info_and_mjcf_say_no_limits(tmp_path):
    from uvms_pin.apps.export.mjcf import uvms_to_mjcf
    from uvms_pin.apps.export.mujoco_state import q_from_qpos, qpos_from_q

    uvms = up.load_uvms(continuous_joint_urdf(tmp_path, ("arm_joint1",)))
    summary = model_summary(uvms)
    arm_table = summary.split("arm joints:")[1]
    line = next(x for x in arm_table.splitlines() if x.strip().startswith("arm_joint1"))
    assert "none" in line and "continuous" in line
    assert "-1.010" not in summary
    urdf_text = continuous_joint_urdf(tmp_path, ("arm_joint1",)).read_text()
    text = uvms_to_mjcf(uvms, urdf_text, base_dir=tmp_path)
    joint = next(x for x in text.splitlines() if 'name="arm_joint1"' in x and "<joint" in x)
    assert "range" not in joint
    other = next(x for x in text.splitlines() if 'name="arm_joint2"' in x and "<joint" in x)
    assert 'range="-0.29999999999999999 2"' in other  # exact (17 digits)
    kinds = uvms.arm_joints.kinds
    q = uvms.neutral_configuration()
    q[7:9] = np.cos(2.5), np.sin(2.5)
    qpos = qpos_from_q(q, kinds)
    assert qpos.shape == (7 + 4,) and qpos[7] == pytest.approx(2.5, abs=1e-15)
    np.testing.assert_allclose(q_from_qpos(qpos, kinds), q, rtol=0, atol=1e-15)
    mujoco = pytest.importorskip("mujoco")
    model = mujoco.MjModel.from_xml_string(text)
    assert model.nq == qpos.size and model.nv == uvms.nv
