"""``uvms-pin compare-arms SCENARIO --arms reference,ur5,panda --out DIR``.

Wire it into `uvms_pin.apps.cli.main.build_parser` with ``register(sub)``; meanwhile run it as
``python -m uvms_pin.apps.arms.command SCENARIO ...``.
"""

from __future__ import annotations

import argparse
import math
import sys

from uvms_pin.apps.arguments import (
    add_comparison_command,
    add_set_option,
    comma_names,
    count,
    finite,
    positive,
    process_count,
    progress_printer,
)
from uvms_pin.apps.exit_codes import EXIT_BAD_INPUT, EXIT_RUN_STOPPED
from uvms_pin.apps.interrupts import InterruptGuard
from uvms_pin.model.mount.catalog import available_arms
from uvms_pin.results.outdir import COMPARISON, check_writable, claim
from uvms_pin.scenario.overrides import parse_assignment

DEFAULT_ARMS = "reference,so100,z1,kinova,ur3,ur5,panda"


def _cmd_compare_arms(args: argparse.Namespace) -> int:
    if args.list:
        print("\n".join(available_arms()))
        return 0
    if args.scenario is None:
        print("uvms-pin compare-arms: error: SCENARIO is required", file=sys.stderr)
        return EXIT_BAD_INPUT
    from uvms_pin.apps.arms.compare import CompareSettings, compare_arms
    from uvms_pin.model.trim import TrimSpec

    arms = comma_names("--arms", args.arms, "arm names")
    trim = None if args.no_trim else TrimSpec(bg_m=args.bg, foam_density_kg_m3=args.foam_density)
    settings = CompareSettings(
        duration_s=args.duration,
        trim=trim,
        mount_rpy=None if args.mount_rpy is None else tuple(args.mount_rpy),
        ik_starts=args.ik_starts,
        keep_rollouts=args.keep_rollouts,
        overrides=tuple(parse_assignment(text) for text in args.set),
    )
    out = check_writable(args.out)
    say = progress_printer(args.quiet)
    # SIGTERM stops the comparison as Ctrl-C does (`uvms_pin.apps.interrupts`), its workers
    # with it
    with InterruptGuard(), claim(out, COMPARISON, overwrite=args.overwrite):
        rows = compare_arms(args.scenario, arms, out, settings, jobs=args.jobs, progress=say)
    width = max(len(r["arm"]) for r in rows)
    for r in rows:
        force, tracking = r["force_error_rms_N"], r["task_position_error_rms_m"]
        err_text = ""
        if not math.isnan(force):
            err_text = f"force error RMS {force:.3f} N"
        elif not math.isnan(tracking):
            err_text = f"tracking position error RMS {tracking * 1e3:.2f} mm"
        print(f"{r['arm']:<{width}}  {r['status']:<16} {err_text}")
    print(f"wrote {args.out}/comparison.csv, comparison.md, comparison.png")
    if args.keep_rollouts:
        print(f"per arm: {args.out}/<arm>/row.json, rollout, metrics.json and figures")
    ran = [r for r in rows if r["simulated_time_s"] > 0.0]  # NaN: it never ran
    if not ran:
        reasons = "; ".join(f"{r['arm']}: {r['status']} ({r['reason']})" for r in rows)
        print(
            f"uvms-pin: compare-arms: no arm ran, nothing is compared: {reasons}", file=sys.stderr
        )
        return EXIT_RUN_STOPPED
    return 0


def register(subparsers) -> argparse.ArgumentParser:
    """Add the ``compare-arms`` subcommand to the ``uvms-pin`` parser's subparsers."""
    parser = add_comparison_command(
        subparsers,
        "compare-arms",
        "run a scenario's task with several arms mounted on its vehicle and compare them",
        "Mount each arm (a name from example-robot-data, 'reference' or a URDF path) on the "
        "scenario's vehicle, solve the initial configuration, trim, run the task and write "
        "comparison.csv, comparison.md and comparison.png.",
        scenario_required=False,
        out_default="out/compare_arms",
    )
    parser.add_argument(
        "--arms",
        default=DEFAULT_ARMS,
        help=f"comma-separated arm names or URDF paths (default {DEFAULT_ARMS})",
    )
    parser.add_argument("--duration", type=positive, default=None, help="override the duration [s]")
    parser.add_argument(
        "--jobs", type=process_count(1), default=1, help="arms run in parallel processes"
    )
    parser.add_argument("--no-trim", action="store_true", help="do not add foam and ballast")
    parser.add_argument(
        "--bg", type=finite, default=0.02, help="metacentric height BG after trim [m]"
    )
    parser.add_argument(
        "--foam-density", type=positive, default=350.0, help="trim foam density [kg/m^3]"
    )
    parser.add_argument(
        "--mount-rpy",
        type=finite,
        nargs=3,
        metavar=("R", "P", "Y"),
        help="every arm's base orientation on the vehicle [rad] (default: each arm's own: a "
        "table-top arm or a URDF given by path upside down, (pi, 0, 0); the Alpha 5 as Reach "
        "mounts it, (0, 0, 0))",
    )
    parser.add_argument(
        "--ik-starts",
        type=count(1, 10_000, "a few dozen suffice"),
        default=24,
        help="initial-configuration search starts",
    )
    parser.add_argument(
        "--keep-rollouts",
        action="store_true",
        help="also write each arm's row, rollout, metrics and figures into OUT/<arm>/",
    )
    add_set_option(
        parser,
        "override a scenario entry for every arm (repeatable), as in 'run'; each arm's model, "
        "initial joint positions and per-joint controller entries are set per arm",
    )
    parser.add_argument("--quiet", action="store_true", help="no progress lines")
    parser.add_argument("--list", action="store_true", help="list the arm names available and exit")
    parser.set_defaults(func=_cmd_compare_arms)
    return parser
