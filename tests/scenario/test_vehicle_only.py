"""A vehicle without an arm (issue 11.1): it loads, shows and runs; what needs an
end-effector says so; models/lbv150.urdf is the reference model's vehicle."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from conftest import REFERENCE_URDF, RHO, ROOT, G, body_urdf, hydro_xml, random_configuration, run

import uvms_pin as up
from uvms_pin.model.mount.split import split_urdf

VEHICLE_URDF = ROOT / "models" / "lbv150.urdf"


def box_rov(write_urdf) -> Path:
    """A box ROV: 20 kg, 0.02 m^3, CoB 5 cm above the CoG, damping and added mass."""
    hydro = hydro_xml(
        0.02, cob=(0, 0, 0.05), added=(5, 8, 9, 0.1, 0.2, 0.2), lin=(10, 12, 14, 1, 1, 1)
    )
    return write_urdf(body_urdf(mass=20.0, hydro=hydro), "box_rov.urdf")


def scenario_text(model: Path, extra: str = "") -> str:
    return textwrap.dedent(
        f"""
        [scenario]
        model = "{model}"
        duration_s = 2.0
        [initial]
        position_world_m = [0.0, 0.0, -2.0]
        [integrator]
        step_s = 0.005
        [output]
        log_period_s = 0.05
        """
    ) + textwrap.dedent(extra)


def test_a_vehicle_without_ee_or_sensor_frame_loads(write_urdf):
    uvms = up.load_uvms(box_rov(write_urdf))
    assert (uvms.nq, uvms.nv, uvms.n_arm_joints) == (7, 6, 0)
    assert uvms.ee_frame_id is None and uvms.sensor_frame_id is None
    assert not uvms.has_end_effector
    assert uvms.net_buoyancy_N == pytest.approx((RHO * 0.02 - 20.0) * G)
    with pytest.raises(up.ModelError, match="PPC needs an end-effector frame"):
        uvms.require_ee_frame("PPC")
    # a frame asked for by name must still exist
    with pytest.raises(up.ModelError, match="frame 'ee' not found"):
        up.load_uvms(box_rov(write_urdf), ee_frame="ee")


def test_the_shipped_vehicle_is_the_reference_model_without_its_arm(tmp_path):
    """lbv150.urdf and the vehicle split off uvms_lbv150.urdf: the same dynamics."""
    alone = up.load_uvms(VEHICLE_URDF)
    split = up.load_uvms(split_urdf(REFERENCE_URDF, tmp_path).vehicle_urdf)
    reference = up.load_uvms(REFERENCE_URDF)
    assert alone.nv == 6 and alone.ee_frame_id is None
    arm_mass = sum(reference.model.inertias[j].mass for j in range(2, reference.model.njoints))
    assert alone.mass_kg == pytest.approx(reference.mass_kg - arm_mass, rel=1e-12)
    rng = np.random.default_rng(11)
    for _ in range(5):
        q = random_configuration(alone, rng)
        v = rng.normal(size=6)
        current = rng.normal(size=3) * 0.3
        np.testing.assert_array_equal(up.mass_matrix(alone, q), up.mass_matrix(split, q))
        np.testing.assert_array_equal(
            up.bias_forces(alone, q, v, current), up.bias_forces(split, q, v, current)
        )
    # the hull is trimmed for the arm: alone it floats up with the arm's weight in water
    arm_net_weight = sum(
        (reference.model.inertias[j].mass - RHO * reference.volume_per_joint_m3[j])
        * np.linalg.norm(reference.model.gravity.linear)
        for j in range(2, reference.model.njoints)
    )
    assert reference.net_buoyancy_N == pytest.approx(0.0, abs=1e-3)  # trimmed (6 digits)
    assert alone.net_buoyancy_N == pytest.approx(
        arm_net_weight + reference.net_buoyancy_N, rel=1e-9
    )
    assert arm_net_weight == pytest.approx(1.31, abs=0.01)  # the URDF header's number


def test_the_model_generator_is_up_to_date():
    """Both URDFs are what models/derive_lbv150.py writes (one source of numbers)."""
    result = subprocess.run(
        [sys.executable, str(ROOT / "models" / "derive_lbv150.py"), "--check"],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr
    assert "lbv150.urdf: up to date" in result.stdout
    assert "uvms_lbv150.urdf: up to date" in result.stdout


def test_info_shows_a_vehicle_alone():
    result = run("info", "lbv150")  # a shipped model name works too
    assert result.returncode == 0, result.stderr
    assert "nq = 7, nv = 6 (6 vehicle + 0 arm joints)" in result.stdout
    assert "end-effector frame: none" in result.stdout
    assert "arm joints: none" in result.stdout


def test_a_passive_vehicle_only_scenario_runs_and_rises(tmp_path, write_urdf):
    """Box ROV, CoB above the CoG, B - W > 0, no input: it rises with a = (B - W) /
    (m + Z_wdot) at first (added mass is inertia), then at the terminal speed where the
    linear damping Z_w w equals B - W."""
    path = tmp_path / "s.toml"
    path.write_text(scenario_text(box_rov(write_urdf)).replace("2.0\n[initial]", "4.0\n[initial]"))
    scenario = up.load_scenario(path)
    rollout = up.simulate(scenario)
    assert rollout.metadata["status"] == "ok"
    assert rollout.metadata["arm_joint_names"] == []
    lift_N = (RHO * 0.02 - 20.0) * G
    mass_z, damping_z = 20.0 + 9.0, 14.0
    t = rollout.time_s
    rise = rollout.q[:, 2] - rollout.q[0, 2]
    # closed form of m w' = F - d w from rest: z(t) = F/d (t - tau (1 - exp(-t/tau)))
    tau = mass_z / damping_z
    expected = lift_N / damping_z * (t - tau * (1.0 - np.exp(-t / tau)))
    np.testing.assert_allclose(rise, expected, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(rollout.q[:, :2], 0.0, atol=1e-12)  # straight up, level
    np.testing.assert_allclose(rollout.q[:, 3:6], 0.0, atol=1e-12)


def test_a_vehicle_only_run_from_the_command_line(tmp_path, write_urdf):
    model = box_rov(write_urdf)
    path = tmp_path / "s.toml"
    path.write_text(scenario_text(model))
    result = run("run", str(path), "--out", str(tmp_path / "out"), "--quiet")
    assert result.returncode == 0, result.stderr
    for name in ("rollout.npz", "metrics.json", "pose.png", "velocities.png"):
        assert (tmp_path / "out" / name).is_file()
    rollout = up.Rollout.load(tmp_path / "out")
    assert rollout.q.shape[1] == 7
    assert rollout.q[-1, 2] > rollout.q[0, 2]  # buoyant: it rises


@pytest.mark.parametrize(
    ("extra", "needle"),
    [
        ("[environment]\ntype = 'spring'\nstiffness_N_m = [2, 2, 2]\n", "[environment]"),
        ("[controller]\ntype = 'ppc'\n", "[controller] type = 'ppc'"),
    ],
)
def test_what_needs_an_end_effector_says_so(tmp_path, extra, needle):
    path = tmp_path / "s.toml"
    path.write_text(scenario_text(VEHICLE_URDF, extra))
    with pytest.raises(up.ScenarioError) as info:
        up.load_scenario(path)
    message = str(info.value)
    assert needle in message and "needs an end-effector frame" in message
    assert "s.toml" in message


def test_a_contact_plant_needs_an_end_effector():
    from uvms_pin.physics.contact import LinearSpring
    from uvms_pin.sim.plant import Plant

    with pytest.raises(up.ModelError, match="needs an end-effector frame"):
        Plant(up.load_uvms(VEHICLE_URDF), contact=LinearSpring(np.ones(3)))
