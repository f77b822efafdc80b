"""The IMU's mounting yaw: its maps, the fit's Jacobian in it against finite differences, the
motion-capture cross-check, and the command line that takes it (and warns of a capped fit)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import run
from scipy.spatial.transform import Rotation
from test_sensitivity import DATA_DIR, initial_state, synthetic_arm

from uvms_pin.apps.validation.fit import simulation_residuals
from uvms_pin.apps.validation.identify import HULL
from uvms_pin.apps.validation.imu_mount import (
    imu_roll_pitch,
    imu_tangent,
    roll_against_mocap_slope,
    start_sensitivity,
    vehicle_start,
)
from uvms_pin.apps.validation.parameters import parameter_values, parse_parameters
from uvms_pin.apps.validation.pool import TrialSetup, compare_trial, trial_uvms
from uvms_pin.apps.validation.prescribed import simulate_prescribed_arm
from uvms_pin.apps.validation.sensitivity import SensitiveModel
from uvms_pin.apps.validation.trials import load_trial, roll_pitch_rad


def test_vehicle_start_and_reading_invert_each_other():
    """Reading the start the IMU measured back in the IMU's axes gives the measurement; the
    rates turn with the frame (|omega| kept); a vehicle pitched by theta reads psi theta of
    roll and theta cos(psi) of pitch."""
    q_imu, nu_imu = initial_state()
    psi = np.radians(3.0)
    q_vehicle, nu_vehicle = vehicle_start(q_imu, nu_imu, psi)
    np.testing.assert_allclose(
        imu_roll_pitch(q_vehicle[None, 3:7], psi), roll_pitch_rad(q_imu[None, 3:7]), atol=1e-12
    )
    np.testing.assert_allclose(q_vehicle[:3], q_imu[:3])
    np.testing.assert_allclose(nu_vehicle[:3], nu_imu[:3])
    np.testing.assert_allclose(np.linalg.norm(nu_vehicle[3:]), np.linalg.norm(nu_imu[3:]))
    # omega_imu = Rz(psi)^T omega_vehicle
    np.testing.assert_allclose(imu_tangent(psi) @ nu_vehicle[3:], nu_imu[3:], atol=1e-12)
    pitched = Rotation.from_euler("ZYX", [0.0, np.radians(10.0), 0.0]).as_quat()
    roll, pitch = imu_roll_pitch(pitched[None], psi)[0]
    assert roll == pytest.approx(psi * np.radians(10.0), rel=0.01)
    assert pitch == pytest.approx(np.radians(10.0) * np.cos(psi), rel=1e-4)


def test_start_sensitivity_is_the_derivative_of_the_start():
    q_imu, nu_imu = initial_state()
    psi, step = 0.05, 1e-6
    q_plus, nu_plus = vehicle_start(q_imu, nu_imu, psi + step)
    q_minus, nu_minus = vehicle_start(q_imu, nu_imu, psi - step)
    q0, nu0 = vehicle_start(q_imu, nu_imu, psi)
    # tangent: R0^T dR (right perturbation)
    rotation0 = Rotation.from_quat(q0[3:7])
    dtheta = (
        (rotation0.inv() * Rotation.from_quat(q_plus[3:7])).as_rotvec()
        - (rotation0.inv() * Rotation.from_quat(q_minus[3:7])).as_rotvec()
    ) / (2 * step)
    expected = start_sensitivity(nu0)
    np.testing.assert_allclose(dtheta, expected[3:6], atol=1e-8)
    np.testing.assert_allclose((nu_plus - nu_minus) / (2 * step), expected[6:], atol=1e-8)
    assert np.all(expected[:3] == 0.0)


def test_fit_jacobian_in_imu_yaw_and_damping_matches_finite_differences():
    """dr/dp of `simulation_residuals` at psi = 3 deg, for the mounting yaw (start and
    reading) and a damping and a centre of buoyancy seen through the turned IMU, against
    central differences of the residual."""
    uvms = trial_uvms()
    parameters = parse_parameters(("imu_yaw", "linear_damping.roll", "center_of_buoyancy.y"))
    arm = synthetic_arm(3.0)
    q0, nu0 = initial_state()
    times = np.linspace(0.0, 3.0, 31)
    q, _ = simulate_prescribed_arm(uvms, arm, q0, nu0, times, 0.02)
    setup = TrialSetup(arm, times, roll_pitch_rad(q[:, 3:7]), q0, nu0)
    values = parameter_values(uvms, parameters, HULL)
    values[:2] = (np.radians(3.0), 0.7)
    _, jac = simulation_residuals(SensitiveModel(uvms, parameters, HULL, values), [setup], 0.02)
    for k, parameter in enumerate(parameters):
        step = 1e-4 * max(abs(values[k]), 1e-2)
        ends = []
        for sign in (1.0, -1.0):
            shifted = values.copy()
            shifted[k] += sign * step
            model = SensitiveModel(uvms, parameters, HULL, shifted)
            ends.append(simulation_residuals(model, [setup], 0.02)[0])
        numeric = (ends[0] - ends[1]) / (2 * step)
        scale = np.abs(numeric).max()
        assert scale > 1e-3, parameter.name
        np.testing.assert_allclose(
            jac[:, k], numeric, rtol=0, atol=2e-4 * scale, err_msg=parameter.name
        )


def test_an_imu_turned_against_the_tracked_frame_shows_in_the_roll_against_pitch_slope():
    """A vehicle pitching through +-10 deg with some roll and yaw, tracked in a frame turned
    -93 deg in yaw (world) and read by an IMU turned 3 deg (body): the slope is 3 deg to 2 %."""
    t = np.linspace(0.0, 20.0, 401)
    euler_zyx = np.column_stack(
        [0.3 * np.sin(0.2 * t), np.radians(10.0) * np.sin(0.4 * t), 0.05 + 0.02 * np.cos(0.3 * t)]
    )
    vehicle = Rotation.from_euler("ZYX", euler_zyx)
    psi = np.radians(3.0)
    imu = (vehicle * Rotation.from_rotvec([0.0, 0.0, psi])).as_quat()
    mocap = (Rotation.from_euler("z", -93.0, degrees=True) * vehicle).as_quat()
    pitch, difference = roll_against_mocap_slope(t, imu, t + 0.001, mocap)
    assert len(pitch) == len(t) and abs(pitch.mean()) < 1e-12
    slope = (pitch @ difference) / (pitch @ pitch)
    assert slope == pytest.approx(psi, rel=0.02)
    # the same IMU without a turn: no slope
    pitch, difference = roll_against_mocap_slope(t, vehicle.as_quat(), t, mocap)
    assert abs((pitch @ difference) / (pitch @ pitch)) < 1e-9


def test_validate_pool_takes_the_imu_yaw_in_degrees(tmp_path):
    """`validate pool --imu-yaw 2` is `compare_trial` with psi = 2 deg, and differs from 0."""
    trial = load_trial(DATA_DIR / "_alt_011-1.npz")
    result = run(
        "validate",
        "pool",
        str(DATA_DIR),
        "--out",
        str(tmp_path),
        "--trials",
        "_alt_011-1",
        "--imu-yaw",
        "2",
        "--no-figures",
    )
    assert result.returncode == 0, result.stderr
    roll = json.loads((tmp_path / "pool_validation.json").read_text())["trials"]["_alt_011-1"]
    turned = compare_trial(trial_uvms(), trial, imu_yaw_rad=np.radians(2.0))
    assert roll["roll_rmse_deg"] == pytest.approx(turned.rmse_deg("simulated")[0], rel=1e-9)
    assert turned.rmse_deg("simulated")[0] != pytest.approx(
        compare_trial(trial_uvms(), trial).rmse_deg("simulated")[0], rel=1e-3
    )


def test_identify_warns_when_the_fit_stops_at_its_cap(monkeypatch, capsys):
    """The command still reports and exits 0, but says on stderr the fit did not converge."""
    from uvms_pin.apps.validation import identify

    def capped(*args, **kwargs):
        trial = {
            "start_roll_rmse_deg": 0.5,
            "start_pitch_rmse_deg": 0.5,
            "identified_roll_rmse_deg": 0.4,
            "identified_pitch_rmse_deg": 0.4,
            "published_roll_rmse_deg": None,
            "published_pitch_rmse_deg": None,
        }
        means = {
            f"mean_{k}_rmse_deg": 0.4
            for k in ("start_roll", "start_pitch", "identified_roll", "identified_pitch")
        }
        return {
            "link": HULL,
            "parameters": {},
            "iterations": 2,
            "accepted_steps": 2,
            "stop_reason": "iteration cap",
            "converged": False,
            "gradient_cosine": 0.1,
            "fit_rms_deg": [0.5, 0.45, 0.4],
            "identification_trials": [],
            "held_out": means,
            "identification": means,
            "trials": {"_alt_011-1": trial},
            "arm_delay_s": 0.0,
            "imu_yaw_rad": 0.0,
        }

    monkeypatch.setattr(identify, "run_identification", capped)
    code = identify.main([str(DATA_DIR), "--fit", "imu_yaw", "--max-iterations", "2"])
    out, err = capsys.readouterr()
    assert code == 0
    assert "stopped: iteration cap (NOT converged)" in out
    assert "stopped at its cap of 2 iterations, not converged" in err
