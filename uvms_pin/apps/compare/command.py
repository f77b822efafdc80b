"""``uvms-pin compare-controllers SCENARIO --controllers ppc,pi_force,... --out DIR``."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from uvms_pin.apps.arguments import (
    add_comparison_command,
    add_set_option,
    comma_names,
    positive,
    process_count,
    progress_printer,
)
from uvms_pin.apps.interrupts import InterruptGuard
from uvms_pin.errors import ParameterError
from uvms_pin.results.outdir import CONTROLLER_COMPARISON, check_writable, claim
from uvms_pin.scenario.overrides import parse_assignment


def _cmd_compare_controllers(args: argparse.Namespace) -> int:
    from uvms_pin.apps.compare.metrics import COLUMNS, Criteria
    from uvms_pin.apps.compare.runs import controller_scenarios

    names = None if args.controllers is None else comma_names("--controllers", args.controllers)
    overrides = dict(parse_assignment(text) for text in args.set)
    scenarios = controller_scenarios(args.scenario, names, overrides)
    names = list(scenarios)
    duration = next(iter(scenarios.values())).settings.duration_s
    after_s = 0.5 * duration if args.after is None else args.after
    if not after_s < duration:
        raise ParameterError(
            f"--after {after_s:g} s must be before the end of the run ({duration:g} s)"
        )
    criteria = Criteria(after_s, args.band, args.tolerance)
    out = check_writable(args.out)
    if next(iter(scenarios.values())).task is not None:
        return _compare_tracking(args, scenarios, criteria, out)
    header = (
        f"Scenario {args.scenario}; force and orientation errors after t = {after_s:g} s, "
        f"settling band {args.band:g} N, success: peak force error after the transient "
        f"<= {args.tolerance:g} N, no joint past its limits."
    )

    def figures_and_robustness(rows, rollouts, say) -> list[Path]:
        written = []
        if not args.no_figures:
            from uvms_pin.apps.compare.figures import write_comparison_figures

            written += write_comparison_figures(rows, rollouts, out, after_s)
        if args.robustness:
            from uvms_pin.apps.compare.robustness import run_robustness, write_robustness

            if say is not None:
                say("robustness set: every controller x 6 cases, through the study runner ...")
            robust = run_robustness(
                args.scenario, names, out / "robustness", criteria, args.jobs, overrides
            )
            written += write_robustness(robust, out)
        return written

    def summary(row) -> str:
        if not math.isfinite(row["force_error_rms_N"]):
            return f"{row['controller']:<16} no errors to judge"  # its reason follows
        return (
            f"{row['controller']:<16} force error RMS {row['force_error_rms_N']:.3f} N, "
            f"peak {row['force_error_peak_N']:.3f} N"
        )

    table = (header, COLUMNS)
    return _compare(args, scenarios, criteria, out, table, figures_and_robustness, summary)


def _compare_tracking(args: argparse.Namespace, scenarios, criteria, out) -> int:
    """The comparison on a tracking task (`uvms_pin.apps.compare.tracking`): its table and
    ``controllers_tracking.png``; ``--robustness`` is for the force task only."""
    from uvms_pin.apps.compare.tracking import TRACKING_COLUMNS, write_tracking_figure

    if args.robustness:
        raise ParameterError("--robustness runs the force-tracking cases: not for a [task]")
    if args.after is not None:
        raise ParameterError(
            "--after is the force task's window: a [task] is judged after its transient_s "
            "(--set task.transient_s=S)"
        )
    task = next(iter(scenarios.values())).task
    header = (
        f"Scenario {args.scenario}; {task.kind} of the {task.target} ({task.frame} frame); "
        f"errors after t = {task.transient_s:g} s; success: the run ends with every joint "
        f"inside its limits and the position error within {task.settle_tolerance_m:g} m."
    )

    def figure(rows, rollouts, say) -> list[Path]:
        return [] if args.no_figures or not rollouts else [write_tracking_figure(rollouts, out)]

    def summary(row) -> str:
        position, orientation = (
            row["task_position_error_rms_m"],
            row["task_orientation_error_rms_rad"],
        )
        if not (math.isfinite(position) and math.isfinite(orientation)):
            return f"{row['controller']:<22} no errors to judge"  # its reason follows
        return (
            f"{row['controller']:<22} position error RMS {1000 * position:.2f} mm, "
            f"orientation {orientation:.4f} rad"
        )

    return _compare(args, scenarios, criteria, out, (header, TRACKING_COLUMNS), figure, summary)


def _compare(args: argparse.Namespace, scenarios, criteria, out: Path, table, extras, summary):
    """Run ``scenarios`` with each controller in the claimed ``out``; write the table
    (``table``: its header and columns) and what ``extras(rows, rollouts, say)`` writes;
    print each controller's ``summary(row)`` with its verdict, and what was written."""
    from uvms_pin.apps.compare.runs import compare_controllers
    from uvms_pin.apps.compare.table import write_table

    # SIGTERM stops the comparison as Ctrl-C does, the robustness set's workers with it
    with InterruptGuard(), claim(out, CONTROLLER_COMPARISON, overwrite=args.overwrite):
        say = progress_printer(args.quiet)
        rows, rollouts = compare_controllers(scenarios, criteria, say)
        written = write_table(rows, out, *table)
        written += extras(rows, rollouts, say)
    for row in rows:
        verdict = "holds the task" if row["success"] else f"fails: {row['reason']}"
        print(f"{summary(row)}: {verdict}")
    print("wrote " + ", ".join(str(p) for p in written))
    return 0


def register(subparsers) -> argparse.ArgumentParser:
    """Add the ``compare-controllers`` subcommand to the ``uvms-pin`` parser."""
    parser = add_comparison_command(
        subparsers,
        "compare-controllers",
        "run a scenario's task with several controllers and compare them",
        "Run the scenario once per controller (its own [controller] for its type, the "
        "[baselines.<name>] tuning for the others, defaults if absent) and write "
        "controllers.csv, controllers.md and figures.",
    )
    parser.add_argument(
        "--controllers",
        default=None,
        help="comma-separated: the scenario's own type, pi_force, impedance, "
        "computed_torque and its named [baselines.<name>] variants (default: its own type, "
        "its variants and, on a force task, the three baselines)",
    )
    add_set_option(
        parser, "override a scenario entry for every controller (repeatable), as in 'run'"
    )
    parser.add_argument(
        "--after", type=positive, default=None, help="start of the after-transient window [s] "
        "(default: half the duration)"
    )  # fmt: skip
    parser.add_argument("--band", type=positive, default=0.25, help="settling band [N]")
    parser.add_argument(
        "--tolerance", type=positive, default=0.5,
        help="largest peak force error after the transient that holds the task [N]",
    )  # fmt: skip
    parser.add_argument("--no-figures", action="store_true", help="tables only")
    parser.add_argument(
        "--robustness",
        action="store_true",
        help="also run every controller on 6 cases (nominal, environment stiffness x10, "
        "plant x1.3 and x0.7, noise x5, disturbance x5) through the study runner: "
        "robustness.csv, robustness.md, OUT/robustness/ (a study directory)",
    )
    parser.add_argument(
        "--jobs", type=process_count(0), default=1,
        help="Dask worker processes for --robustness (0: serial, in this process)",
    )  # fmt: skip
    parser.add_argument("--quiet", action="store_true", help="no progress lines")
    parser.set_defaults(func=_cmd_compare_controllers)
    return parser
