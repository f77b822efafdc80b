"""The shipped BlueROV2 Heavy, trial vehicle and Reach Alpha 5 match their published figures."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import uvms_pin as up
from uvms_pin.model.mount.catalog import CATALOG, resolve_arm

ROOT = Path(__file__).resolve().parents[2]
MODELS = ROOT / "models"
BLUEROV = MODELS / "bluerov2_heavy.urdf"
TRIAL = MODELS / "bluerov2_heavy_hinsdale2023.urdf"
ALPHA5 = MODELS / "reach_alpha5.urdf"
MOUNT = ((0.25, -0.10965, 0.005), (0.0, 0.0, 0.0))
G = 9.81


def _vehicle(path: Path, rho: float = 1025.0) -> up.UVMS:
    # a vehicle-only URDF has no 'ee' / 'ft_sensor' frames: name its root for both
    return up.load_uvms(
        path, water_density_kg_m3=rho, ee_frame="base_link", sensor_frame="base_link"
    )


def _hull(uvms: up.UVMS) -> up.HydroBody:
    return next(b for b in uvms.hydro_bodies if b.name == "base_link")


def test_generated_files_are_current():
    done = subprocess.run(
        [sys.executable, str(MODELS / "derive_bluerov_alpha5.py"), "--check"],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stdout + done.stderr


def test_bluerov2_heavy_matches_von_benzon_table_a1():
    uvms = _vehicle(BLUEROV)
    assert uvms.nv == 6
    assert uvms.mass_kg == pytest.approx(13.5)
    assert uvms.volume_m3 == pytest.approx(0.0134)
    inertia = uvms.model.inertias[1]
    np.testing.assert_allclose(np.diag(inertia.inertia), [0.26, 0.23, 0.37])
    np.testing.assert_allclose(inertia.lever, 0.0, atol=1e-12)
    hull = _hull(uvms).params
    np.testing.assert_allclose(hull.center_of_buoyancy_m, [0.0, 0.0, 0.01])  # r_b above r_g
    np.testing.assert_allclose(np.diag(hull.added_mass), [6.36, 7.12, 18.68, 0.189, 0.135, 0.222])
    np.testing.assert_allclose(np.diag(hull.linear_damping), [13.7, 0, 33.0, 0, 0.8, 0])
    np.testing.assert_allclose(hull.quadratic_damping, [141, 217, 190, 1.19, 0.47, 1.5])


def test_bluerov2_heavy_added_mass_enters_the_mass_matrix():
    uvms = _vehicle(BLUEROV)
    mass = up.mass_matrix(uvms, uvms.neutral_configuration())
    np.testing.assert_allclose(
        np.diag(mass),
        [13.5 + 6.36, 13.5 + 7.12, 13.5 + 18.68, 0.26 + 0.189, 0.23 + 0.135, 0.37 + 0.222],
    )


def test_bluerov2_heavy_restoring_moment_is_w_bg_sin_roll():
    """Level: buoyancy through G -> no moment; rolled by phi: M = -rho g V BG sin(phi)."""
    uvms = _vehicle(BLUEROV, rho=1000.0)
    q = uvms.neutral_configuration()
    phi = 0.2
    q[3:7] = [np.sin(phi / 2), 0.0, 0.0, np.cos(phi / 2)]
    h = up.bias_forces(uvms, q, np.zeros(6))
    # h holds minus the external moment: +rho g V BG sin(phi) about body x
    assert h[3] == pytest.approx(1000.0 * G * 0.0134 * 0.01 * np.sin(phi), rel=1e-9)


def test_trial_vehicle_is_kolano_hardware_configuration():
    """Weight 13.17 kg + ballast/DVL net weights; buoyancy 13.082 kg + foam lift (fresh water)."""
    uvms = _vehicle(TRIAL, rho=997.0)
    hull = _hull(uvms).params
    assert 997.0 * hull.volume_m3 == pytest.approx(13.082)
    # K23's centre of buoyancy plus the correction identified on the identification trials
    np.testing.assert_allclose(
        hull.center_of_buoyancy_m, [0.0074 + 0.000306, 0.000546, 0.02 + 0.004211], atol=1e-12
    )
    net_items_N = 3.24 + 1.62 + 1.62 + 0.69 + 1.01 - 8.46 - 8.86
    hull_net_N = (13.082 - 13.17) * G
    assert uvms.net_buoyancy_N == pytest.approx(-(net_items_N) + hull_net_N, abs=1e-6)


def test_alpha5_masses_volumes_and_limits():
    arm = up.load_uvms(
        ALPHA5,
        water_density_kg_m3=997.0,
        ee_frame="alpha_jaw_link",
        sensor_frame="alpha_wrist_link",
    )
    # K23 MagicNumAlpha: masses [kg] and volumes [L] of base, shoulder, upper arm, elbow, wrist, jaw
    assert arm.mass_kg == pytest.approx(0.341 + 0.194 + 0.429 + 0.115 + 0.333 + 0.05)
    assert arm.volume_m3 == pytest.approx((0.202 + 0.018 + 0.203 + 0.025 + 0.155 + 0.02) * 1e-3)
    assert arm.arm_joint_names == ["alpha_axis_e", "alpha_axis_d", "alpha_axis_c", "alpha_axis_b"]
    np.testing.assert_allclose(arm.model.effortLimit[6:], [9, 9, 9, 5])
    np.testing.assert_allclose(
        np.degrees(arm.model.upperPositionLimit[7:]), [175, 200, 200, 165], rtol=1e-8
    )
    np.testing.assert_allclose(np.degrees(arm.model.lowerPositionLimit[7:]), [-175, 0, 0, -165])


@pytest.mark.parametrize(
    "name",
    ["reach_alpha5", "reach_alpha5_jaws", "uvms_bluerov2_alpha5", "uvms_bluerov2_alpha5_jaws"],
)
def test_every_alpha5_file_carries_its_drives_reflected_rotor_inertia(name):
    """J_rotor N^2 on each arm joint: Reach's gear ratios (1754.4 on axes E, D, C; 340.4 on
    the wrist) times the estimated rotor inertias (2e-8 and 1e-7 kg m^2), through the
    mount into the merged files; no armature elsewhere (the fingers, the vehicle)."""
    kwargs = {} if name.startswith("uvms_") else {"ee_frame": "alpha_wrist_link",
                                                  "sensor_frame": "alpha_wrist_link"}  # fmt: skip
    uvms = up.load_uvms(MODELS / f"{name}.urdf", **kwargs)
    model = uvms.model
    expected = {"alpha_axis_e": 0.0616, "alpha_axis_d": 0.0616, "alpha_axis_c": 0.0616,
                "alpha_axis_b": 0.0116}  # fmt: skip
    armature = np.zeros(model.nv)
    for joint, value in expected.items():
        idx_v = model.joints[model.getJointId(joint)].idx_v
        armature[idx_v] = value
        assert value == pytest.approx(
            {"alpha_axis_b": 1e-7 * 340.4**2}.get(joint, 2e-8 * 1754.4**2), rel=2e-3
        )
    np.testing.assert_array_equal(model.armature, armature)
    # the wrist about its own axis: its link's 8e-5 kg m^2 and the drive's 0.0116
    mass = up.mass_matrix(uvms, uvms.neutral_configuration())
    wrist = model.joints[model.getJointId("alpha_axis_b")].idx_v
    assert 0.0116 < mass[wrist, wrist] < 0.0116 + 2e-4


@pytest.mark.parametrize("vehicle", [BLUEROV, TRIAL])
def test_alpha5_mounts_on_both_bluerov_models(vehicle):
    uvms = up.mount_arm(vehicle, ALPHA5, MOUNT, tool=None, water_density_kg_m3=997.0)
    assert uvms.nv == 10
    assert uvms.arm_joint_names == ["alpha_axis_e", "alpha_axis_d", "alpha_axis_c", "alpha_axis_b"]
    vehicle_alone = _vehicle(vehicle, rho=997.0)
    assert uvms.mass_kg == pytest.approx(vehicle_alone.mass_kg + 1.462)
    mass = up.mass_matrix(uvms, uvms.neutral_configuration())
    np.testing.assert_allclose(mass, mass.T, atol=1e-12)
    assert np.all(np.linalg.eigvalsh(mass) > 0.0)


def test_trial_configuration_is_nearly_neutral():
    """Kolano's trim: the vehicle with its arm floats up very slightly (a few 0.01 N)."""
    uvms = up.mount_arm(TRIAL, ALPHA5, MOUNT, tool=None, water_density_kg_m3=997.0)
    assert 0.0 < uvms.net_buoyancy_N < 0.1


def test_alpha5_is_in_the_arm_catalog():
    entry = resolve_arm("alpha5")
    assert entry is CATALOG["alpha5"]
    assert entry.urdf.is_file()
    assert entry.urdf.name == "reach_alpha5.urdf"


def test_force_task_model_is_trimmed_neutral_with_probe():
    uvms = up.load_uvms(MODELS / "uvms_bluerov2_alpha5.urdf")
    assert uvms.nv == 10
    assert abs(uvms.net_buoyancy_N) < 1e-3
    assert uvms.model.frames[uvms.ee_frame_id].name == "ee"
    assert uvms.model.frames[uvms.sensor_frame_id].name == "ft_sensor"
    assert uvms.mass_kg > _vehicle(BLUEROV).mass_kg + 1.462  # + probe, foam and ballast
