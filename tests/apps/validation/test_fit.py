"""Levenberg-Marquardt identification: it recovers the parameters synthetic trials were
simulated with, and `uvms-pin identify --fit` refuses bad input and writes a usable model."""

from __future__ import annotations

import json
import re
import shutil

import numpy as np
import pytest
from conftest import run
from test_sensitivity import DATA_DIR, initial_state, synthetic_arm

from uvms_pin.apps.validation import fit as fit_module
from uvms_pin.apps.validation.figures import identified_figure
from uvms_pin.apps.validation.fit import _damped_step, _gradient_cosine, fit_parameters
from uvms_pin.apps.validation.identify import HULL
from uvms_pin.apps.validation.imu_mount import imu_roll_pitch, vehicle_start
from uvms_pin.apps.validation.parameters import (
    hydro_body,
    parameter_values,
    parse_parameters,
    with_parameters,
)
from uvms_pin.apps.validation.pool import (
    IDENTIFICATION_TRIALS,
    TrialSetup,
    compare_trial,
    trial_uvms,
)
from uvms_pin.apps.validation.prescribed import simulate_prescribed_arm
from uvms_pin.apps.validation.trials import load_trial
from uvms_pin.errors import ParameterError
from uvms_pin.model.mount.text import urdf_text
from uvms_pin.model.resources import shipped_path
from uvms_pin.model.urdf.write_hydro import urdf_with_hydro

NAMES = (
    "linear_damping.roll",
    "linear_damping.pitch",
    "quadratic_damping.roll",
    "center_of_buoyancy.y",
    "added_mass.roll",
)


def _synthetic_trials(uvms, rng, noise_rad: float, imu_yaw_rad: float = 0.0) -> list[TrialSetup]:
    """Two 5 s trials (the arm's motion shifted in time) simulated with ``uvms``, roll and
    pitch measured with white noise by an IMU turned ``imu_yaw_rad`` on the hull (the setup
    holds what that IMU measured at the start)."""
    setups = []
    for shift_s, roll_rate in ((0.0, 0.25), (1.7, -0.3)):
        arm = synthetic_arm(5.0 + shift_s)
        times = np.arange(shift_s, shift_s + 5.0 + 1e-9, 0.05)
        q0, nu0 = initial_state()
        nu0[3] = roll_rate
        q_vehicle0, nu_vehicle0 = vehicle_start(q0, nu0, imu_yaw_rad)
        q, _ = simulate_prescribed_arm(uvms, arm, q_vehicle0, nu_vehicle0, times, 0.05)
        noise = rng.normal(scale=noise_rad, size=(len(times), 2))
        measured = imu_roll_pitch(q[:, 3:7], imu_yaw_rad) + noise
        setups.append(TrialSetup(arm, times, measured, q0, nu0))
    return setups


def _truth(catalogue, parameters) -> np.ndarray:
    """Roll and pitch linear damping 2.5 and 1.8 N m s, roll quadratic damping 3 N m s^2, the
    centre of buoyancy 2 mm off to the side, the roll added mass doubled."""
    return parameter_values(catalogue, parameters, HULL) + np.array([2.5, 1.0, 1.81, 0.002, 0.189])


def test_fit_recovers_the_parameters_of_exact_synthetic_trials():
    """Without noise, from the catalogue values (0, 0.8, 1.19, shipped r_B, 0.189), the fit
    finds the truth to 1e-6 (the Jacobian is right: Gauss-Newton converges quadratically)."""
    parameters = parse_parameters(NAMES)
    catalogue = trial_uvms()
    truth = _truth(catalogue, parameters)
    synthetic = with_parameters(catalogue, parameters, truth, HULL)
    setups = _synthetic_trials(synthetic, np.random.default_rng(1), 0.0)
    fit = fit_parameters(catalogue, setups, parameters, HULL, 0.05, max_iterations=20)
    assert fit.rms_deg[0] > 0.3  # the start is far off the data
    assert fit.rms_deg[-1] < 1e-6
    np.testing.assert_allclose(fit.values, truth, rtol=1e-6)
    assert parameter_values(fit.uvms, parameters, HULL) == pytest.approx(fit.values)
    # it stopped by itself, converged, before the cap
    assert fit.converged and fit.stop_reason == "exact"
    assert fit.iterations < 20


def test_fit_says_it_stopped_at_its_cap_and_refuses_bad_tolerances():
    """One step from far off is not convergence: the fit says so (`iteration cap`)."""
    parameters = parse_parameters(NAMES[:2])
    catalogue = trial_uvms()
    truth = parameter_values(catalogue, parameters, HULL) + np.array([2.5, 1.0])
    synthetic = with_parameters(catalogue, parameters, truth, HULL)
    setups = _synthetic_trials(synthetic, np.random.default_rng(1), 0.0)[:1]
    lines = []
    fit = fit_parameters(
        catalogue, setups, parameters, HULL, 0.05, max_iterations=1, progress=lines.append
    )
    assert fit.iterations == 1 and fit.stop_reason == "iteration cap" and not fit.converged
    assert lines[0].startswith("start: RMS") and lines[-1].endswith("iteration cap")
    assert fit.rms_deg[-1] < fit.rms_deg[0]  # the one step still lowered the cost
    with pytest.raises(ParameterError, match="cost_tolerance must be > 0"):
        fit_parameters(catalogue, setups, parameters, HULL, 0.05, cost_tolerance=0.0)
    with pytest.raises(ParameterError, match="max_iterations must be >= 1"):
        fit_parameters(catalogue, setups, parameters, HULL, 0.05, max_iterations=0)


def test_fit_recovers_an_imu_mounting_yaw_with_the_damping():
    """Synthetic trials read by an IMU turned 3 deg on the hull: from psi = 0 the fit finds
    psi and the roll damping to 1e-6 (the start's and the reading's sensitivities are right),
    and stops converged."""
    parameters = parse_parameters(("imu_yaw", "linear_damping.roll", "center_of_buoyancy.y"))
    catalogue = trial_uvms()
    truth = parameter_values(catalogue, parameters, HULL) + np.array([np.radians(3.0), 1.5, 0.001])
    synthetic = with_parameters(catalogue, parameters, truth, HULL)
    setups = _synthetic_trials(synthetic, np.random.default_rng(1), 0.0, truth[0])
    fit = fit_parameters(catalogue, setups, parameters, HULL, 0.05, max_iterations=20)
    assert fit.rms_deg[0] > 0.1 and fit.rms_deg[-1] < 1e-6
    np.testing.assert_allclose(fit.values, truth, rtol=1e-6)
    assert fit.converged


def test_fit_recovers_the_parameters_of_noisy_synthetic_trials():
    """With 0.05 deg of white noise on roll and pitch, the fit explains the data down to the
    noise and finds the parameters within what the noise allows: 5 % for the linear damping
    and the added mass, 2 % of the shift of r_B, 20 % for the quadratic roll damping (it
    trades off against the linear one at these rates)."""
    parameters = parse_parameters(NAMES)
    catalogue = trial_uvms()
    truth = _truth(catalogue, parameters)
    synthetic = with_parameters(catalogue, parameters, truth, HULL)
    setups = _synthetic_trials(synthetic, np.random.default_rng(2024), np.radians(0.05))
    fit = fit_parameters(catalogue, setups, parameters, HULL, 0.05, max_iterations=30)
    assert fit.rms_deg[-1] < 0.05  # ~ the noise (the fit absorbs a little of it)
    assert fit.stop_reason in ("gradient", "cost", "step") and fit.iterations < 30
    np.testing.assert_allclose(fit.values[:2], truth[:2], rtol=0.05)
    np.testing.assert_allclose(fit.values[2], truth[2], rtol=0.2)
    assert abs(fit.values[3] - truth[3]) < 0.02 * 0.002
    np.testing.assert_allclose(fit.values[4], truth[4], rtol=0.05)


def test_identified_vehicle_urdf_is_the_identified_model(tmp_path):
    """The URDF written for an identified hull loads back (through `validate pool
    --vehicle`'s `trial_uvms`) as the same model: same hull coefficients, same simulation."""
    parameters = parse_parameters(("linear_damping.roll", "center_of_buoyancy.z"))
    uvms = trial_uvms()
    values = parameter_values(uvms, parameters, HULL) + np.array([1.234, -0.001])
    identified = with_parameters(uvms, parameters, values, HULL)
    path = tmp_path / "vehicle.urdf"
    params = hydro_body(identified, HULL).params
    path.write_text(
        urdf_text(
            urdf_with_hydro(shipped_path("models/bluerov2_heavy_hinsdale2023.urdf"), HULL, params)
        )
    )
    loaded = trial_uvms(path)
    assert hydro_body(loaded, HULL).params == params
    trial = load_trial(DATA_DIR / "_alt_011-1.npz")
    direct, via_file = compare_trial(identified, trial), compare_trial(loaded, trial)
    np.testing.assert_allclose(via_file.simulated, direct.simulated, rtol=0, atol=1e-12)
    result = run(
        "validate",
        "pool",
        str(DATA_DIR),
        "--out",
        str(tmp_path / "v"),
        "--trials",
        "_alt_011-1",
        "--vehicle",
        str(path),
        "--no-figures",
    )
    assert result.returncode == 0, result.stderr
    summary = json.loads((tmp_path / "v" / "pool_validation.json").read_text())
    roll, _ = direct.rmse_deg("simulated")
    assert summary["trials"]["_alt_011-1"]["roll_rmse_deg"] == pytest.approx(roll, rel=1e-9)


@pytest.mark.parametrize(
    ("fit", "message"),
    [
        ("linear_damping.roll,spring.x", "unknown parameter 'spring.x'"),
        ("center_of_buoyancy.yaw", "center_of_buoyancy has x, y, z"),
        ("linear_damping.roll,,", "none empty"),
        ("default,imu_yaw", "parameter given twice: imu_yaw"),  # default holds it
    ],
)
def test_identify_refuses_unknown_parameters_before_writing(tmp_path, fit, message):
    out = tmp_path / "out"
    result = run("identify", str(DATA_DIR), "--fit", fit, "--out", str(out))
    assert result.returncode == 2, result.stderr
    assert message in result.stderr and "Traceback" not in result.stderr
    assert not out.exists()


def test_identify_names_a_missing_identification_trial(tmp_path):
    for name in IDENTIFICATION_TRIALS[1:]:
        shutil.copy(DATA_DIR / f"{name}.npz", tmp_path)
    out = tmp_path / "out"
    result = run("identify", str(tmp_path), "--fit", "linear_damping.roll", "--out", str(out))
    assert result.returncode == 2
    assert "identification trial(s) _alt_001-0 missing" in result.stderr
    assert "Traceback" not in result.stderr and not out.exists()
    result = run("identify", str(tmp_path / "nope"), "--fit", "linear_damping.roll")
    assert result.returncode == 2 and "not a directory" in result.stderr


def test_identified_figure_takes_runs_on_windows_an_arm_delay_moved(tmp_path):
    uvms, trial = trial_uvms(), load_trial(DATA_DIR / "_alt_011-1.npz")
    start, delayed = compare_trial(uvms, trial), compare_trial(uvms, trial, arm_delay_s=0.25)
    assert len(start.time_s) != len(delayed.time_s)
    assert identified_figure(start, delayed, tmp_path / "f.png").stat().st_size > 10_000


def test_identify_refuses_a_step_longer_than_the_imu_intervals(tmp_path):
    out = tmp_path / "out"
    result = run("identify", str(DATA_DIR), "--fit", "arm_delay", "--step", "10", "--out", str(out))
    assert result.returncode == 2
    assert "--step 10 s is longer than the longest IMU interval" in result.stderr
    assert not out.exists()


def _rosenbrock(uvms, parameters, link, values, setups, step_s):
    """r = (10 (p1 - p0^2), 1 - p0) and its Jacobian, in place of the trials' simulation."""
    p0, p1 = values
    return np.array([10.0 * (p1 - p0**2), 1.0 - p0]), np.array([[-20.0 * p0, 10.0], [-1.0, 0.0]])


def test_fit_damps_a_step_that_overshoots_and_reaches_the_minimum(monkeypatch):
    """On Rosenbrock's residual from (-1.2, 1) the first Gauss-Newton step raises the cost
    (to 1171 from 12.1): it is rejected, lambda grows (x4) until a step lowers the cost, and
    the fit ends at the minimum (1, 1). (A lambda that shrank on rejection would retry the
    same overshoot until the iteration cap.)"""
    monkeypatch.setattr(fit_module, "_evaluate", _rosenbrock)
    parameters = parse_parameters(("center_of_buoyancy.y", "center_of_buoyancy.z"))
    messages = []
    result = fit_parameters(
        trial_uvms(), [], parameters, HULL, 0.05, start=np.array([-1.2, 1.0]),
        max_iterations=200, progress=messages.append,
    )  # fmt: skip
    assert result.converged and result.stop_reason in ("exact", "gradient")
    np.testing.assert_allclose(result.values, [1.0, 1.0], atol=1e-6)
    assert "iteration 1: rejected (lambda -> 0.004)" in messages
    assert all(b < a for a, b in zip(result.rms_deg, result.rms_deg[1:], strict=False))


def test_a_parameter_held_at_its_bound_leaves_the_step_and_the_gradient_test():
    """Linear residual r = J p - b with two coupled columns, p0 >= 0 held at 0 by a gradient
    pushing it below: the step leaves p0 at 0 and gives p1 the least-squares value with p0
    = 0 (not the coupled step projected afterwards), and the gradient cosine leaves p0's
    outward component out (p1's is then 0 at that point); a free parameter's step past its
    bound stops at the bound."""
    jac = np.array([[1.0, 1.0], [0.0, 1.0], [1.0, -0.5]])
    b = np.array([-1.0, 2.0, -0.5])
    floor = np.array([0.0, -np.inf])
    values = np.array([0.0, 0.0])
    assert (jac.T @ (jac @ values - b))[0] > 0.0  # pushes p0 below its bound
    candidate, _ = _damped_step(values, jac @ values - b, jac, 1e-12, floor)
    best_p1 = jac[:, 1] @ b / (jac[:, 1] @ jac[:, 1])
    np.testing.assert_allclose(candidate, [0.0, best_p1], rtol=1e-9, atol=1e-12)
    at_best = np.array([0.0, best_p1])
    assert _gradient_cosine(jac @ at_best - b, jac, at_best, floor) < 1e-12
    inside = np.array([0.05, best_p1])  # p0 free (above its bound): its step goes below
    candidate, _ = _damped_step(inside, jac @ inside - b, jac, 1e-12, floor)
    assert candidate[0] == 0.0


def _three_trials(tmp_path):
    """A data folder of trials outside the shipped identification split."""
    tmp_path.mkdir(exist_ok=True)
    for name in ("_alt_002-0", "_alt_009-1", "_alt_011-1"):
        shutil.copy(DATA_DIR / f"{name}.npz", tmp_path)
    return tmp_path


def test_identify_fits_on_the_trials_train_names_and_holds_out_the_others(tmp_path):
    """--train chooses the identification trials (a folder without families 001 and 008):
    the fit runs on them, identification.json names them, the figures are the others'."""
    data, out = _three_trials(tmp_path / "data"), tmp_path / "out"
    result = run(
        "identify", str(data), "--fit", "linear_damping.roll", "--train", "_alt_011-1",
        "--max-iterations", "2", "--out", str(out), "--quiet",
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    summary = json.loads((out / "identification.json").read_text())
    assert summary["identification_trials"] == ["_alt_011-1"]
    assert set(summary["trials"]) == {"_alt_002-0", "_alt_009-1", "_alt_011-1"}
    assert "_alt_011-1 (identification)" in result.stdout
    assert "_alt_002-0 (held out)" in result.stdout
    assert summary["parameters"]["linear_damping.roll"]["unit"] == "N m s/rad"
    assert re.search(r"linear_damping.roll: \S+ -> \S+ N m s/rad \(analytic\)", result.stdout)
    figures = sorted(p.name for p in out.glob("identified*.png"))
    assert figures == ["identified_alt_002-0.png", "identified_alt_009-1.png"]


def test_identify_quasi_static_fit_on_the_trials_train_names(tmp_path):
    """Without --fit, the centre-of-buoyancy fit on the --train trials: the library's fit
    on the same two trials, printed."""
    from uvms_pin.apps.validation.identify import fit_centre_of_buoyancy

    data = _three_trials(tmp_path)
    result = run("identify", str(data), "--train", "_alt_002-0,_alt_009-1")
    assert result.returncode == 0, result.stderr
    assert "identification trials: _alt_002-0, _alt_009-1" in result.stdout
    printed = result.stdout.split("dr_B = [")[1].split("]")[0]
    offset, _, _ = fit_centre_of_buoyancy(
        trial_uvms(), [data / "_alt_002-0.npz", data / "_alt_009-1.npz"]
    )
    np.testing.assert_allclose(np.array(printed.split(), dtype=float), offset, atol=1e-6)


@pytest.mark.parametrize(
    ("train", "message"),
    [
        ("_alt_099-0", "identification trial(s) _alt_099-0 missing"),
        ("_alt_002-0,_alt_009-1,_alt_011-1", "no trial left to hold out"),
        ("_alt_002-0,,_alt_009-1", "none empty"),
        ("_alt_002-0,_alt_002-0", "given twice"),
    ],
)
def test_identify_refuses_a_bad_train_list_before_writing(tmp_path, train, message):
    data, out = _three_trials(tmp_path / "data"), tmp_path / "out"
    result = run(
        "identify", str(data), "--fit", "linear_damping.roll", "--train", train, "--out", str(out)
    )
    assert result.returncode == 2, result.stderr
    assert message in result.stderr and "Traceback" not in result.stderr
    assert not out.exists()


@pytest.mark.parametrize(
    ("name", "unit"),
    [
        ("linear_damping.x", "N s/m"),
        ("linear_damping.pitch", "N m s/rad"),
        ("quadratic_damping.z", "N s^2/m^2"),
        ("quadratic_damping.yaw", "N m s^2/rad^2"),
        ("added_mass.y", "kg"),
        ("added_mass.roll", "kg m^2"),
        ("center_of_buoyancy.z", "m"),
        ("arm_delay", "s"),
        ("imu_yaw", "rad"),
    ],
)
def test_every_identifiable_parameter_has_its_si_unit(name, unit):
    (parameter,) = parse_parameters((name,))
    assert parameter.unit == unit
