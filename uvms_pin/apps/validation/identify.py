"""Identify the trial vehicle's centre of buoyancy from the pool trials' quasi-static attitude.

The arm moves slowly, so the vehicle stays close to its hydrostatic equilibrium: at each
instant, the roll and pitch where the restoring moment of gravity and buoyancy balances
the arm's (the roll and pitch rows of h(q, 0) vanish). The equilibrium depends on where
the hull's centre of buoyancy is; a shift dr_B of a fraction of a centimetre moves it by
degrees (roll stiffness ~ W BG ~ 3 N m/rad for ~150 N of buoyancy). This module fits dr_B
(3 numbers) by least squares of equilibrium minus measured roll and pitch on a set of
trials, and reports the fit on the others:

    python -m uvms_pin.apps.validation.identify data/hinsdale2023
    python -m uvms_pin.apps.validation.identify data/hinsdale2023 --cob 0.0074 0 0.02

The fit is relative to the model it starts from: the shipped trial model already carries
the correction (an offset of ~0 comes out); ``--cob`` starts from another hull centre of
buoyancy, e.g. Kolano's own (0.0074, 0, 0.02) m, from which the correction is found.

Identification trials: the trajectory families 001 and 008 (6 trials); the families 002,
009 and 011 (6 trials) are held out for validation (`IDENTIFICATION_TRIALS`). ``--train``
names others (file stems); the rest of the folder is then held out.

With ``--fit NAMES`` (e.g. ``linear_damping.roll,center_of_buoyancy.y``), the named hull
parameters are fitted instead on the simulation error of the whole trials, by
Levenberg-Marquardt with sensitivities propagated along the simulation
(`uvms_pin.apps.validation.identification`); ``--out DIR`` writes the identified vehicle.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from uvms_pin.apps.arguments import progress_printer
from uvms_pin.apps.validation.identification import IDENTIFIED_VEHICLE, run_identification
from uvms_pin.apps.validation.identify_arguments import (
    add_identify_arguments,
    check_identify_arguments,
    fit_names,
    training_trials,
)
from uvms_pin.apps.validation.pool import (
    IDENTIFICATION_TRIALS,
    JOINT_CUTOFF_HZ,
    joint_angles_rad,
    trial_uvms,
)
from uvms_pin.apps.validation.prescribed import JointTrajectory
from uvms_pin.apps.validation.trials import load_trial, roll_pitch_rad, split_trials
from uvms_pin.errors import SimulationError
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.dynamics import bias_forces
from uvms_pin.results.outdir import IDENTIFICATION, claim

__all__ = [
    "IDENTIFICATION_TRIALS",
    "fit_centre_of_buoyancy",
    "quasi_static_roll_pitch",
    "with_cob",
    "with_cob_offset",
]

HULL = "base_link"


def with_cob_offset(uvms: UVMS, offset_m: np.ndarray, link: str = HULL) -> UVMS:
    """The same system with ``link``'s centre of buoyancy moved by offset_m (link frame)."""

    def moved(body):
        if body.name != link:
            return body.params
        cob = body.params.center_of_buoyancy_m + np.asarray(offset_m, dtype=float)
        return dataclasses.replace(body.params, center_of_buoyancy_m=cob)

    return uvms.with_hydro(moved)


def with_cob(uvms: UVMS, cob_m: Sequence[float], link: str = HULL) -> UVMS:
    """The same system with ``link``'s centre of buoyancy at cob_m (link frame) [m]."""
    (body,) = [b for b in uvms.hydro_bodies if b.name == link]
    return with_cob_offset(
        uvms, np.asarray(cob_m, dtype=float) - body.params.center_of_buoyancy_m, link
    )


def _restoring_roll_pitch(uvms: UVMS, roll_pitch: np.ndarray, q_arm: np.ndarray) -> np.ndarray:
    quat = Rotation.from_euler("ZYX", [0.0, roll_pitch[1], roll_pitch[0]]).as_quat()
    q = np.concatenate([np.zeros(3), quat, q_arm])
    return bias_forces(uvms, q, np.zeros(uvms.nv))[3:5]


def quasi_static_roll_pitch(
    uvms: UVMS, q_arm: np.ndarray, guess_rad: np.ndarray, tol_rad: float = 1e-8
) -> np.ndarray:
    """Roll and pitch [rad] (yaw 0) where the roll and pitch moments of h(q, 0) vanish.

    Newton's method with a finite-difference Jacobian, from ``guess_rad``.

    Raises:
        SimulationError: no convergence in 20 iterations (e.g. an unstable trim).
    """
    x = np.asarray(guess_rad, dtype=float).copy()
    eps = 1e-6
    for _ in range(20):
        f0 = _restoring_roll_pitch(uvms, x, q_arm)
        jac = np.column_stack(
            [(_restoring_roll_pitch(uvms, x + eps * e, q_arm) - f0) / eps for e in np.eye(2)]
        )
        step = np.linalg.solve(jac, -f0)
        x += step
        if np.max(np.abs(step)) < tol_rad:
            return x
    raise SimulationError(f"no hydrostatic equilibrium found near {guess_rad} for q_arm {q_arm}")


def _samples(path: Path, every: int) -> tuple[list[np.ndarray], np.ndarray]:
    """Prescribed arm angles and measured roll/pitch at every ``every``-th IMU sample."""
    trial = load_trial(path)
    arm = JointTrajectory.from_samples(
        trial.encoder_time_s, joint_angles_rad(trial.encoder_rad), JOINT_CUTOFF_HZ
    )
    start, end = trial.common_span_s
    arm_start, arm_end = arm.span_s
    inside = (trial.imu_time_s >= max(start, arm_start)) & (trial.imu_time_s <= min(end, arm_end))
    times = trial.imu_time_s[inside][::every]
    measured = roll_pitch_rad(trial.imu_quat_xyzw[inside][::every])
    return [arm(t)[0] for t in times], measured


def _errors(uvms: UVMS, data) -> np.ndarray:
    out = []
    for arm_angles, measured in data:
        for q_arm, rp in zip(arm_angles, measured, strict=True):
            out.append(quasi_static_roll_pitch(uvms, q_arm, rp) - rp)
    return np.array(out)


def rms_deg(errors: np.ndarray) -> str:
    """'roll, pitch' RMS [deg] of (n, 2) errors [rad], 3 decimals."""
    roll, pitch = np.degrees(np.sqrt(np.mean(errors**2, axis=0)))
    return f"{roll:.3f}, {pitch:.3f}"


def fit_centre_of_buoyancy(
    uvms: UVMS, trial_files: Sequence[Path], every: int = 10
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Least-squares dr_B [m] of the hull; also the errors [rad] before and after."""
    data = [_samples(p, every) for p in trial_files]
    result = least_squares(
        lambda p: _errors(with_cob_offset(uvms, p), data).ravel(),
        np.zeros(3),
        diff_step=1e-3,
        x_scale=0.005,
    )
    before = _errors(uvms, data)
    return result.x, before, result.fun.reshape(-1, 2)


def _quasi_static(args, start: UVMS) -> int:
    """The centre-of-buoyancy fit on the quasi-static attitude, printed."""
    names = training_trials(args)
    training, held_out = split_trials(args.data_dir, names)
    offset, before, after = fit_centre_of_buoyancy(start, training, args.every)
    print(f"identification trials: {', '.join(names)}")
    millimetres = ", ".join(f"{round(1e3 * x, 2) + 0.0:.2f}" for x in offset)  # no -0.00
    print(
        f"hull centre of buoyancy offset dr_B = {np.array2string(offset, precision=6)} m "
        f"= ({millimetres}) mm"
    )
    print(
        "quasi-static roll, pitch RMS [deg] on identification trials: "
        f"{rms_deg(before)} -> {rms_deg(after)}"
    )
    data = [_samples(p, args.every) for p in held_out]
    moved = with_cob_offset(start, offset)
    print(
        "quasi-static roll, pitch RMS [deg] on held-out trials: "
        f"{rms_deg(_errors(start, data))} -> {rms_deg(_errors(moved, data))}"
    )
    return 0


def _print_fit(result: dict) -> None:
    print(f"identification trials: {', '.join(result['identification_trials'])}")
    accepted = len(result["fit_rms_deg"]) - 1
    stop = result["stop_reason"]
    state = "converged" if result["converged"] else "NOT converged"
    print(
        f"{result['link']}: {result['iterations']} Levenberg-Marquardt steps tried, "
        f"{accepted} accepted; stopped: {stop} ({state})"
    )
    for name, p in result["parameters"].items():
        print(
            f"  {name}: {p['start']:.6g} -> {p['identified']:.6g} {p['unit']} ({p['sensitivity']})"
        )
    for which in ("identification", "held_out"):
        m = result[which]
        print(
            f"{which.replace('_', '-')} trials, mean roll, pitch RMSE [deg]: "
            f"{m['mean_start_roll_rmse_deg']:.3f}, {m['mean_start_pitch_rmse_deg']:.3f} -> "
            f"{m['mean_identified_roll_rmse_deg']:.3f}, {m['mean_identified_pitch_rmse_deg']:.3f}"
        )
    for name, t in result["trials"].items():
        kind = "identification" if name in result["identification_trials"] else "held out"
        published = t["published_roll_rmse_deg"]
        extra = "" if published is None else f" (published simulator: {published:.3f})"
        print(
            f"  {name} ({kind}): roll {t['start_roll_rmse_deg']:.3f} -> "
            f"{t['identified_roll_rmse_deg']:.3f}{extra}, pitch {t['start_pitch_rmse_deg']:.3f}"
            f" -> {t['identified_pitch_rmse_deg']:.3f}"
        )


def run(args: argparse.Namespace) -> int:
    """``identify``: the quasi-static centre-of-buoyancy fit, or with ``--fit`` the dynamic
    fit of the named parameters (`uvms_pin.apps.validation.identification`); ``args`` as
    `check_identify_arguments` passed them."""
    # the shipped trial model may already hold a correction: fit the one relative to the file
    start = trial_uvms() if args.cob is None else with_cob(trial_uvms(), args.cob)
    if args.fit is None:
        return _quasi_static(args, start)
    with _claimed(args):
        result = run_identification(
            args.data_dir,
            args.out,
            fit_names(args),
            start=start,
            step_s=args.step,
            max_iterations=args.max_iterations,
            figures=not args.no_figures,
            progress=progress_printer(args.quiet),
            training=training_trials(args),
        )
    _print_fit(result)
    if not result["converged"]:
        print(
            f"warning: the fit stopped at its cap of {args.max_iterations} iterations, not "
            "converged: raise --max-iterations",
            file=sys.stderr,
        )
    if args.out is not None:
        print(f"wrote {args.out}/identification.json, {IDENTIFIED_VEHICLE}")
        recording = ""
        if result["arm_delay_s"]:
            recording += f" --arm-delay {result['arm_delay_s']:.6g}"
        if result["imu_yaw_rad"]:
            recording += f" --imu-yaw {np.degrees(result['imu_yaw_rad']):.6g}"
        if recording:
            print(f"validate with: --vehicle {args.out}/{IDENTIFIED_VEHICLE}{recording}")
    return 0


def _claimed(args: argparse.Namespace) -> contextlib.AbstractContextManager:
    """``--out`` claimed for the identification while it runs (`claim`: refused when it
    holds another command's results, or an earlier identification's without
    ``--overwrite``); nothing without ``--out``."""
    if args.out is None:
        return contextlib.nullcontext()
    return claim(args.out, IDENTIFICATION, overwrite=args.overwrite)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_identify_arguments(parser)
    args = parser.parse_args(argv)
    check_identify_arguments(args)
    return run(args)


if __name__ == "__main__":
    sys.exit(main())
