"""The ``sweep`` and ``report`` subcommands (``register(subparsers)`` adds them to a CLI).

    uvms-pin sweep STUDY.toml --out DIR [--workers N | --scheduler ADDRESS] [--keep-rollouts]
    uvms-pin report DIR

Until they are wired into ``uvms-pin``: ``python -m uvms_pin.apps.study.command sweep ...``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from uvms_pin.apps.arguments import nonempty, path_text, process_count
from uvms_pin.apps.interrupts import InterruptGuard, stop_status
from uvms_pin.results.outdir import STUDY, check_writable, claim


def _cmd_sweep(args: argparse.Namespace) -> int:
    from uvms_pin.apps.study.reader import load_study
    from uvms_pin.apps.study.runner import load_results, run_study

    study = load_study(args.study)  # every check happens here, before any run
    runs = study.runs()
    out = check_writable(args.out)
    # SIGTERM (a batch system's time limit, `kill`) stops the sweep as Ctrl-C does: the
    # workers stopped with it, not left running on their own
    with InterruptGuard(), claim(out, STUDY, overwrite=args.overwrite):
        where = f"scheduler {args.scheduler}" if args.scheduler else _workers_text(args.workers)
        print(f"study {study.name}: {len(runs)} runs of {study.base} on {where}, results in {out}")
        try:
            summary = run_study(
                study,
                out,
                workers=args.workers,
                scheduler=args.scheduler,
                keep_rollouts=args.keep_rollouts,
                progress=not args.quiet,
                retry_errors=args.retry_errors,
            )
        except KeyboardInterrupt as exc:  # Ctrl-C, or SIGTERM (`Terminated`)
            status, stopped = stop_status(exc)
            recorded = len(load_results(out))
            print(
                f"\n{stopped}: {recorded} of {len(runs)} runs recorded in {out}; "
                "rerun the same command to finish",
                file=sys.stderr,
            )
            return status
    print(
        f"{summary['run']} run now, {summary['skipped']} already recorded; "
        + ", ".join(
            f"{k} {summary.get(k, 0)}" for k in ("ok", "FunnelViolation", "diverged", "error")
        )
    )
    print(f"table: {Path(args.out) / 'results.parquet'}")
    return 0


def _workers_text(workers: int | None) -> str:
    if workers == 0:
        return "this process (serial)"
    if workers == 1:
        return "1 local worker process"
    return f"{workers or 'cpu-count'} local worker processes"


def _cmd_report(args: argparse.Namespace) -> int:
    from uvms_pin.apps.study.report import write_report

    written = write_report(args.directory)
    print(f"wrote {written[0]} and {len(written) - 1} figures in {Path(args.directory)}")
    return 0


def register(subparsers) -> None:
    """Add ``sweep`` and ``report`` to an ``argparse`` subparsers object."""
    sweep = subparsers.add_parser(
        "sweep",
        help="run a study (parameter sweep / Monte Carlo) on Dask into a Parquet table",
        description="Run every run of a study file not yet recorded in --out (rerun to resume).",
    )
    sweep.add_argument("study", type=path_text, help="study TOML file")
    sweep.add_argument(
        "--out", required=True, type=path_text, help="output directory (table, parts, rollouts)"
    )
    where = sweep.add_mutually_exclusive_group()
    where.add_argument(
        "--workers",
        type=process_count(0),
        default=None,
        help="local worker processes, forked (1 thread each; default: CPU count; 0 = serial)",
    )
    where.add_argument(
        "--scheduler",
        type=nonempty("an address"),
        help="address of a running Dask scheduler (tcp://host:8786)",
    )
    sweep.add_argument(
        "--keep-rollouts", action="store_true", help="save every rollout in DIR/rollouts/<run id>/"
    )
    sweep.add_argument(
        "--retry-errors",
        action="store_true",
        help="rerun recorded runs whose status is 'error' (crashes, not funnel violations)",
    )
    sweep.add_argument("--quiet", action="store_true", help="no progress bar")
    sweep.add_argument(
        "--overwrite",
        action="store_true",
        help="discard the study results in --out first (to rerun a changed study there)",
    )
    sweep.set_defaults(func=_cmd_sweep)

    report = subparsers.add_parser(
        "report",
        help="figures and a Markdown summary (report.md) of a study's results",
        description="Scatter and box plots of metrics vs parameters, funnel-violation heatmaps, report.md.",
    )
    report.add_argument("directory", type=path_text, help="output directory of 'sweep'")
    report.set_defaults(func=_cmd_report)
