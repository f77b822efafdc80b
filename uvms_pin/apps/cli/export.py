"""``uvms-pin export RUN_DIR --mcap FILE``: a saved run as a ROS 2 bag (docs/ros.md)."""

from __future__ import annotations

import argparse
from pathlib import Path

from uvms_pin.apps.arguments import path_text
from uvms_pin.errors import UvmsPinError


def _cmd_export(args: argparse.Namespace) -> int:
    if not args.mcap:
        raise UvmsPinError("export: nothing to do, give --mcap FILE")
    from uvms_pin.apps.export.ros_bag import write_mcap
    from uvms_pin.results.outdir import claim_file
    from uvms_pin.results.rollout import ARRAY_FILE, Rollout

    if not (Path(args.run) / ARRAY_FILE).is_file():
        _refuse_several_robots(Path(args.run))
    rollout = Rollout.load(args.run)
    path = Path(args.mcap)
    with claim_file(path, overwrite=args.overwrite, option="--mcap"):
        write_mcap(rollout, path, urdf=args.urdf)
    size_mb = path.stat().st_size / 1e6
    print(f"wrote {path} ({size_mb:.1f} MB, {len(rollout)} samples)")
    return 0


def _refuse_several_robots(run: Path) -> None:
    """UvmsPinError when ``run`` holds a run of several robots: a bag is one robot's."""
    from uvms_pin.errors import ParameterError
    from uvms_pin.results.robots import RobotRollouts

    try:
        robots = RobotRollouts.names_in(run)
    except ParameterError:
        return  # not one either: Rollout.load says what is missing
    raise UvmsPinError(
        f"export: {run} holds a run of several robots ({', '.join(robots)}): a bag is one "
        f"robot's, e.g. uvms-pin export {run / robots[0]} --mcap FILE"
    )


def register(sub) -> None:
    parser = sub.add_parser(
        "export", help="write a saved run in another format: a ROS 2 bag (MCAP)"
    )
    parser.add_argument(
        "run", type=path_text, help="directory holding rollout.npz and rollout.json"
    )
    parser.add_argument(
        "--mcap",
        type=path_text,
        help='the MCAP file to write (ROS 2 messages, CDR); needs pip install "uvms-pin[ros]"',
    )
    parser.add_argument(
        "--urdf", type=path_text, help="the model's URDF, if it moved since the run"
    )
    parser.add_argument("--overwrite", action="store_true", help="replace an existing file")
    parser.set_defaults(func=_cmd_export)
