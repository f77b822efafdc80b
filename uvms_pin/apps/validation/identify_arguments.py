"""The arguments of ``uvms-pin identify`` (and of ``python -m uvms_pin.apps.validation.identify``),
apart from the fitting code so that the command line stays light to import."""

from __future__ import annotations

import argparse

from uvms_pin.apps.arguments import count, finite, nonempty, path_text, positive

__all__ = ["add_identify_arguments"]


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
