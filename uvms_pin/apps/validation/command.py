"""``uvms-pin validate pool DATA_DIR --out DIR``: the pool trials against the simulator;
``uvms-pin identify DATA_DIR``: the trial vehicle's parameters fitted to them.

Wired into `uvms_pin.apps.cli.main.build_parser` with ``register(sub)``.
"""

from __future__ import annotations

import argparse
import math

from uvms_pin.apps.arguments import (
    comma_names,
    finite,
    nonempty,
    path_text,
    positive,
    progress_printer,
)
from uvms_pin.apps.validation.identify_arguments import (
    add_identify_arguments,
    check_identify_arguments,
)
from uvms_pin.results.outdir import OVERWRITE_HELP, POOL_VALIDATION, check_writable, claim


def _cmd_validate_pool(args: argparse.Namespace) -> int:
    from uvms_pin.apps.validation.trials import select_trials

    names = None if args.trials is None else comma_names("--trials", args.trials, "trial names")
    check_writable(args.out)  # before minutes of simulation, not after
    select_trials(args.data_dir, names)  # at once: the simulation code takes seconds to import
    from uvms_pin.apps.validation.run import run_pool_validation

    with claim(args.out, POOL_VALIDATION, overwrite=args.overwrite):
        result = run_pool_validation(
            args.data_dir,
            args.out,
            trial_names=names,
            step_s=args.step,
            figures=not args.no_figures,
            progress=progress_printer(args.quiet),
            vehicle_urdf=args.vehicle,
            arm_delay_s=args.arm_delay,
            imu_yaw_rad=math.radians(args.imu_yaw),
        )
    print(
        f"{len(result['trials'])} trials: mean roll RMSE {result['mean_roll_rmse_deg']:.3f} deg, "
        f"mean pitch RMSE {result['mean_pitch_rmse_deg']:.3f} deg"
    )
    figures = "" if args.no_figures else " and one figure per trial"
    print(f"wrote {args.out}/pool_validation.json, pool_validation.csv{figures}")
    return 0


def _cmd_identify(args: argparse.Namespace) -> int:
    check_identify_arguments(args)  # at once: the fitting code takes seconds to import
    from uvms_pin.apps.validation.identify import run

    return run(args)


def register(subparsers) -> argparse.ArgumentParser:
    """Add ``validate pool`` to the ``uvms-pin`` parser's subparsers."""
    parser = subparsers.add_parser(
        "validate", help="compare the simulator with measurements (pool trials)"
    )
    kinds = parser.add_subparsers(dest="validation", required=True)
    pool = kinds.add_parser(
        "pool",
        help="BlueROV2 Heavy + Alpha 5 pool trials: simulated vs measured roll and pitch",
        description=(
            "For every trial (<name>.npz) in DATA_DIR, prescribe the arm joints from the "
            "encoders, leave the vehicle free from its measured initial state and compare the "
            "simulated roll and pitch with the IMU. Writes DIR/pool_validation.json, "
            "pool_validation.csv and <trial>.png."
        ),
    )
    pool.add_argument(
        "data_dir",
        type=path_text,
        help="directory of trial files, e.g. the shipped data/hinsdale2023",
    )
    pool.add_argument("--out", required=True, type=path_text, help="output directory")
    pool.add_argument("--overwrite", action="store_true", help=OVERWRITE_HELP)
    pool.add_argument(
        "--trials", type=nonempty("trial names"), help="comma-separated trial names (default: all)"
    )
    pool.add_argument(
        "--step",
        type=positive,
        default=0.05,
        help="largest RK4 step [s]: each IMU interval is split into equal steps no longer than "
        "this; at most the longest IMU interval (default 0.05, the median interval)",
    )
    pool.add_argument(
        "--vehicle",
        type=path_text,
        help="the trial vehicle's URDF instead of the shipped one, e.g. the identified "
        "vehicle `uvms-pin identify --out DIR` writes (DIR/bluerov2_heavy_identified.urdf)",
    )
    pool.add_argument(
        "--arm-delay",
        type=finite,
        default=0.0,
        metavar="S",
        help="the encoder stream is this late on the IMU's clock [s] (default 0; "
        "`uvms-pin identify --fit ...,arm_delay` fits it)",
    )
    pool.add_argument(
        "--imu-yaw",
        type=finite,
        default=0.0,
        metavar="DEG",
        help="the IMU is mounted turned by this yaw on the hull [deg] (default 0; "
        "`uvms-pin identify --fit ...,imu_yaw` fits it)",
    )
    pool.add_argument("--no-figures", action="store_true", help="skip the per-trial figures")
    pool.add_argument("--quiet", action="store_true", help="no per-trial progress lines")
    pool.set_defaults(func=_cmd_validate_pool)
    identify = subparsers.add_parser(
        "identify",
        help="fit the pool-trial vehicle's hydrodynamic parameters, report held-out trials",
        description=(
            "Fit the trial vehicle's hull parameters on the identification trials of DATA_DIR "
            "(families 001 and 008) and report the held-out ones: by default its centre of "
            "buoyancy on the quasi-static attitude; with --fit, the named parameters on the "
            "simulation error by Levenberg-Marquardt."
        ),
    )
    add_identify_arguments(identify)
    identify.set_defaults(func=_cmd_identify)
    return parser
