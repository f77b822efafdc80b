"""The arguments of ``uvms-pin identify`` (and of ``python -m uvms_pin.apps.validation.identify``),
apart from the fitting code so that the command line stays light to import, and their checks:
every one is checked before the fitting code (SciPy's signal processing, matplotlib) is
imported or a trial read, so a bad one is refused at once."""

from __future__ import annotations

import argparse

from uvms_pin.apps.arguments import comma_names, count, finite, nonempty, path_text, positive
from uvms_pin.errors import ParameterError
from uvms_pin.results.outdir import OVERWRITE_HELP

__all__ = ["add_identify_arguments", "check_identify_arguments", "fit_names", "training_trials"]


def add_identify_arguments(parser: argparse.ArgumentParser) -> None:
    """The arguments of ``identify`` (also ``python -m uvms_pin.apps.validation.identify``)."""
    parser.add_argument("data_dir", type=path_text, help="the pool trials, e.g. data/hinsdale2023")
    parser.add_argument(
        "--every", type=count(1), default=10, help="quasi-static fit: every n-th IMU sample"
    )
    parser.add_argument(
        "--cob",
        nargs=3,
        type=finite,
        metavar=("X", "Y", "Z"),
        help="start from this hull centre of buoyancy [m] (base_link frame) instead of the "
        "shipped model's, e.g. Kolano's 0.0074 0 0.02",
    )
    parser.add_argument(
        "--fit",
        type=nonempty("parameter names"),
        help="comma-separated hull parameters to fit on the simulation error, each "
        "<kind>.<axis>: linear_damping, quadratic_damping, added_mass along x, y, z, roll, "
        "pitch, yaw, or center_of_buoyancy.x|y|z, arm_delay (how late the encoders are "
        "on the IMU's clock [s]) and imu_yaw (the IMU's mounting yaw on the hull [rad]); 'default': roll and pitch linear and quadratic damping, "
        "the centre of buoyancy, arm_delay and imu_yaw, also with more names, e.g. "
        "default,added_mass.roll (without --fit: the quasi-static centre-of-buoyancy fit)",
    )
    parser.add_argument(
        "--out",
        type=path_text,
        help="with --fit: write identification.json, the identified vehicle's URDF and a "
        "figure per held-out trial here",
    )
    parser.add_argument("--overwrite", action="store_true", help=OVERWRITE_HELP)
    parser.add_argument(
        "--train",
        type=nonempty("trial names"),
        metavar="TRIALS",
        help="comma-separated names of the trials to fit on (file names without .npz, e.g. "
        "_alt_001-0,_alt_002-1); the others in DATA_DIR are held out (default: the families "
        "001 and 008)",
    )
    parser.add_argument("--step", type=positive, default=0.05, help="largest RK4 step [s]")
    parser.add_argument(
        "--max-iterations",
        type=count(1),
        default=50,
        help="cap on the Levenberg-Marquardt steps tried (default 50); the fit stops earlier "
        "once converged (residual orthogonal to the Jacobian, or a step that lowers the cost "
        "by < 1e-5 relative or moves no parameter); it says why it stopped",
    )
    parser.add_argument("--no-figures", action="store_true", help="skip the figures")
    parser.add_argument("--quiet", action="store_true", help="no per-iteration progress lines")


def training_trials(args: argparse.Namespace) -> tuple[str, ...]:
    """The identification trials' names: ``--train`` (comma-separated), else the shipped
    split (`IDENTIFICATION_TRIALS`)."""
    from uvms_pin.apps.validation.trials import IDENTIFICATION_TRIALS

    if args.train is None:
        return IDENTIFICATION_TRIALS
    return tuple(comma_names("--train", args.train, "trial names"))


def fit_names(args: argparse.Namespace) -> list[str]:
    """``--fit``'s parameter names, 'default' standing for `DEFAULT_FIT` (alone or with more
    names)."""
    from uvms_pin.apps.validation.parameters import DEFAULT_FIT

    names = []
    for name in comma_names("--fit", args.fit, "parameter names"):
        names += list(DEFAULT_FIT) if name == "default" else [name]
    return names


def check_identify_arguments(args: argparse.Namespace) -> None:
    """Refuse what ``identify`` would refuse later, before anything slow: ``--out`` without
    ``--fit`` or not writable, unknown or repeated ``--fit`` names, a trial folder without
    the identification trials or without a held-out one, a trial file that is no NPZ archive
    or too large for memory (their sizes read from the archives' directories, not the data).
    The step against the trials' IMU intervals is checked once they are read.

    Raises:
        ParameterError: a bad option. DataError: a bad trial folder or file.
    """
    from uvms_pin.apps.validation.parameters import parse_parameters
    from uvms_pin.apps.validation.trials import check_trials_fit, split_trials
    from uvms_pin.results.outdir import check_writable

    if args.fit is None and args.out is not None:
        raise ParameterError(
            f"--out {args.out}: only with --fit (the quasi-static centre-of-buoyancy fit, "
            "without --fit, prints its result and writes nothing)"
        )
    if args.fit is not None:
        parse_parameters(fit_names(args))
    if args.out is not None:
        check_writable(args.out)  # before minutes of fitting, not after
    fitted_on, held_out = split_trials(args.data_dir, training_trials(args))
    check_trials_fit(fitted_on + held_out)
