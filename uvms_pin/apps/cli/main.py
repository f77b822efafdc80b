"""The ``uvms-pin`` command."""

from __future__ import annotations

import argparse
import os
import sys
import warnings
from pathlib import Path
from typing import TYPE_CHECKING

from uvms_pin.apps.arguments import add_set_option, path_text, positive, say_user_traceback
from uvms_pin.apps.arms.command import register as register_compare_arms
from uvms_pin.apps.cli.export import register as register_export
from uvms_pin.apps.cli.run import LIVE_PORTS, check_view_options, cmd_run
from uvms_pin.apps.compare.command import register as register_compare_controllers
from uvms_pin.apps.exit_codes import (
    EXIT_BAD_INPUT,
    EXIT_BROKEN_PIPE,
    EXIT_ENVIRONMENT,
    EXIT_INTERRUPTED,
)
from uvms_pin.apps.interrupts import sigterm_stops, stop_status
from uvms_pin.apps.study.command import register as register_study_commands
from uvms_pin.apps.validation.command import register as register_validate
from uvms_pin.errors import OutputError, UvmsPinError, UvmsPinWarning
from uvms_pin.model.resources import resolve_model
from uvms_pin.results.outdir import OVERWRITE_HELP, check_writable, claim_file

if TYPE_CHECKING:
    from uvms_pin.results.rollout import Rollout

# The simulation stack (Pinocchio, SciPy, matplotlib) is imported by the commands that
# need it: --help, --version and argument errors answer at once.


def _write_replay(rollout: Rollout, path: Path, **kw) -> Path:
    from uvms_pin.apps.viz.replay import write_replay

    return write_replay(rollout, path, **kw)


def _cmd_replay(args: argparse.Namespace) -> int:
    check_view_options(args)
    if not (args.html or args.live):
        raise UvmsPinError("replay: nothing to do, give --html and/or --live")
    from uvms_pin.results.rollout import Rollout

    robots = _robots_in(Path(args.rollout), args)
    rollout = Rollout.load(args.rollout) if robots is None else robots.robot(robots.names[0])
    if args.html:
        path = Path(args.out) if args.out else Path(args.rollout) / "replay.html"
        with claim_file(path, overwrite=args.overwrite):
            if robots is None:
                _write_replay(rollout, path, urdf=args.urdf, max_fps=args.fps, show=args.show)
            else:
                from uvms_pin.apps.viz.robots_replay import write_robots_replay

                write_robots_replay(robots, path, max_fps=args.fps, show=args.show)
        size_mb = path.stat().st_size / 1e6
        print(f"wrote {path} ({size_mb:.1f} MB, {len(rollout)} samples)")
    if args.live == "foxglove":
        from uvms_pin.apps.export.ros_bag import SavedRunTopics, rollout_model
        from uvms_pin.apps.viz.foxglove_live import replay_foxglove

        topics = SavedRunTopics(rollout, rollout_model(rollout, args.urdf))
        replay_foxglove(rollout, topics, port=args.port, speed=args.speed, out=sys.stdout)
    elif args.live:
        from uvms_pin.apps.viz.live import replay_live
        from uvms_pin.apps.viz.replay import scene_for_rollout

        scene = scene_for_rollout(rollout, urdf=args.urdf, show=args.show)
        replay_live(rollout, scene, port=args.port, speed=args.speed, out=sys.stdout)
    return 0


def _robots_in(run: Path, args: argparse.Namespace):
    """The `RobotRollouts` of a run of several robots in ``run`` (its page draws every
    robot), or None for one robot's run. UvmsPinError for what such a run cannot give: a
    live view or a --urdf (one robot's each)."""
    from uvms_pin.errors import ParameterError
    from uvms_pin.results.robots import RobotRollouts

    try:
        names = RobotRollouts.names_in(run)
    except ParameterError:
        return None  # one robot's run, or none: Rollout.load says what is missing
    for option, given in (("--live", args.live), ("--urdf", args.urdf)):
        if given:
            raise UvmsPinError(
                f"replay: {run} holds a run of several robots ({', '.join(names)}); {option} "
                f"is one robot's: give its directory, e.g. uvms-pin replay {run / names[0]} "
                f"{option}"
            )
    return RobotRollouts.load(run)


def _add_view_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--live",
        nargs="?",
        const="meshcat",
        choices=sorted(LIVE_PORTS),
        help="show the run live on 127.0.0.1: in meshcat (--live, --live meshcat: a browser "
        "page) or in Foxglove (--live foxglove: a Foxglove WebSocket server with the ROS 2 "
        'topics of the MCAP export; pip install "uvms-pin[foxglove]")',
    )
    parser.add_argument(
        "--port",
        type=int,
        default=None,
        help="live view port (default 7000 for meshcat, 8765 for Foxglove; 0: any free)",
    )
    parser.add_argument(
        "--speed", type=positive, default=1.0, help="live playback speed-up over real time"
    )
    parser.add_argument(
        "--show",
        choices=("visual", "collision", "both"),
        default="visual",
        help="the robot as drawn in meshcat (--html, --live): its URDF <visual> geometry, its "
        "<collision> shapes (translucent orange) or both",
    )


def _cmd_info(args: argparse.Namespace) -> int:
    from uvms_pin.model.summary import model_summary
    from uvms_pin.model.urdf.load import load_uvms

    uvms = load_uvms(resolve_model(args.urdf), water_density_kg_m3=args.water_density)
    print(model_summary(uvms))
    return 0


def _cmd_import(args: argparse.Namespace) -> int:
    from uvms_pin.model.importer.convert import import_model

    out = Path(args.out)
    table = Path(args.thrusters) if args.thrusters else out.with_suffix(".thrusters.toml")
    with claim_file(out, overwrite=args.overwrite, option="--out"):
        if table.exists() and not args.overwrite:
            raise OutputError(f"--thrusters {table}: exists; pass --overwrite to replace it")
        check_writable(table.parent, "--thrusters", shown=str(table))
        result = import_model(
            args.file, out, thrusters_out=table, allow_dry=args.allow_dry,
            balance_inertia=args.balance_inertia,
        )  # fmt: skip
    print(f"wrote {out}")
    if result.thrusters:
        print(f"wrote {table} ({len(result.thrusters)} thrusters)")
    if result.fluid_density_kg_m3 is not None:
        print(
            f"fluid density in the source: {result.fluid_density_kg_m3:g} kg/m^3 ([water] density_kg_m3)"
        )
    for note in result.grouped_notes():  # the URDF's header comment has each one
        print(f"not mapped: {note}")
    return 0


def _add_import(sub) -> None:
    parser = sub.add_parser(
        "import",
        help="read a Gazebo vehicle (uuv_simulator or gz-sim plugins; URDF or SDF) into a "
        "uvms-pin URDF and a thruster table",
    )
    parser.add_argument("file", help="URDF (xacro-expanded) or SDF file")
    parser.add_argument("--out", required=True, help="the uvms-pin URDF to write")
    parser.add_argument(
        "--thrusters", help="the thruster table to write (default: OUT with .thrusters.toml)"
    )
    parser.add_argument("--overwrite", action="store_true", help="replace existing files")
    parser.add_argument(
        "--allow-dry",
        action="store_true",
        help="import a file that carries no hydrodynamics at all (every link dry)",
    )
    parser.add_argument(
        "--balance-inertia",
        action="store_true",
        help="a link's inertia no mass distribution has (I1 + I2 < I3; Gazebo does not check "
        "it): raise its smallest principal moment to I3 - I2 instead of refusing it",
    )
    parser.set_defaults(func=_cmd_import)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="uvms-pin", description="Underwater vehicle-manipulator simulation on Pinocchio."
    )
    parser.add_argument("--version", action=_Version)
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="run a scenario file and write rollout, metrics and figures")
    run.add_argument("scenario", type=path_text, help="scenario TOML file")
    run.add_argument("--out", required=True, type=path_text, help="output directory")
    run.add_argument("--quiet", action="store_true", help="no progress line")
    run.add_argument("--overwrite", action="store_true", help=OVERWRITE_HELP)
    add_set_option(
        run,
        "override a scenario entry (repeatable): a dotted key, its parts optionally "
        "[i]-indexed, and a TOML value, e.g. --set 'environment.stiffness_N_m=[20,20,20]' "
        "--set 'initial.joint_positions_rad[3]=0.5' "
        "--set 'actuation.thruster[0].max_forward_N=10'; a table value replaces a whole "
        "table: --set 'controller={type=\"none\"}'",
    )
    run.add_argument(
        "--html", action="store_true", help="also write replay.html (self-contained, offline)"
    )
    run.add_argument(
        "--no-code",
        action="store_true",
        help="refuse a scenario that would import a module (a module:Class controller, a "
        "metric function) or read a file outside its folder and the shipped models: for "
        "files of unknown origin (docs/security.md)",
    )
    _add_view_options(run)
    run.set_defaults(func=cmd_run)
    replay = sub.add_parser("replay", help="show a saved rollout: replay.html and/or live")
    replay.add_argument(
        "rollout", type=path_text, help="directory holding rollout.npz and rollout.json"
    )
    replay.add_argument("--html", action="store_true", help="write ROLLOUT/replay.html")
    replay.add_argument(
        "--out", type=path_text, help="write the page here instead of ROLLOUT/replay.html"
    )
    replay.add_argument(
        "--urdf", type=path_text, help="the model's URDF, if it moved since the run"
    )
    replay.add_argument("--overwrite", action="store_true", help="replace an existing page")
    replay.add_argument(
        "--fps", type=positive, default=30.0, help="replay frames per simulated second (max)"
    )
    _add_view_options(replay)
    replay.set_defaults(func=_cmd_replay)
    info = sub.add_parser("info", help="print a summary of a UVMS URDF")
    info.add_argument(
        "urdf",
        type=path_text,
        help="URDF file with the hydrodynamic extension, or a shipped model name",
    )
    info.add_argument(
        "--water-density", type=positive, default=1025.0, help="kg/m^3 (default: sea water)"
    )
    info.set_defaults(func=_cmd_info)
    _add_import(sub)
    register_export(sub)
    register_study_commands(sub)
    register_compare_arms(sub)
    register_compare_controllers(sub)
    register_validate(sub)
    return parser


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """The project's warnings as one line each, like its errors (no source location)."""
    if issubclass(category, UvmsPinWarning):
        print(f"uvms-pin: warning: {message}", file=sys.stderr)
    else:
        sys.stderr.write(warnings.formatwarning(message, category, filename, lineno, line))


class _Version(argparse.Action):
    """``--version``: the text is made only when asked (it imports Pinocchio)."""

    def __init__(self, option_strings, dest, **kw):
        kw.update(nargs=0, help="print the versions of uvms-pin, Pinocchio and Python, and exit")
        super().__init__(option_strings, dest, **kw)

    def __call__(self, parser, namespace, values, option_string=None):
        print(version_text())
        parser.exit()


def version_text() -> str:
    """``uvms-pin X (pinocchio Y, Python Z)``: what a bug report needs."""
    from uvms_pin.results.provenance import package_versions

    versions = package_versions()
    return f"uvms-pin {versions['uvms-pin']} (pinocchio {versions['pin']}, Python {versions['python']})"


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    with warnings.catch_warnings():
        warnings.simplefilter("always", UvmsPinWarning)
        warnings.showwarning = _show_warning
        return _dispatch(args)


def _dispatch(args: argparse.Namespace) -> int:
    try:
        with sigterm_stops():
            return args.func(args)
    except BrokenPipeError:  # the reader of stdout stopped (| head): nothing more to say
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_BROKEN_PIPE
    except OSError as exc:  # a disk full, a file removed under us: not a bug to trace
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"uvms-pin: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return EXIT_ENVIRONMENT
    except UvmsPinError as exc:
        say_user_traceback(exc.user_traceback)  # the user's own code failed: its frames
        print(f"uvms-pin: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except (KeyboardInterrupt, RuntimeError) as exc:
        if isinstance(exc, RuntimeError) and not _caused_by_ctrl_c(exc):
            raise
        status, stopped = (
            stop_status(exc)
            if isinstance(exc, KeyboardInterrupt)
            else (EXIT_INTERRUPTED, "interrupted")
        )
        print(f"uvms-pin: {stopped}", file=sys.stderr)
        return status


def _caused_by_ctrl_c(exc: BaseException) -> bool:
    """Whether a KeyboardInterrupt is the cause of ``exc``: Python turns one raised inside a
    class body's ``__set_name__`` (a Ctrl-C landing in an import) into a RuntimeError."""
    cause = exc.__cause__
    while cause is not None:
        if isinstance(cause, KeyboardInterrupt):
            return True
        cause = cause.__cause__
    return False


if __name__ == "__main__":
    sys.exit(main())
