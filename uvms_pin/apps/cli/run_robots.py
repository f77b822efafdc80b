"""``uvms-pin run`` of a scenario with ``[[robots]]``: every robot's results in a directory
of its name, and ``metrics.json`` (a block per robot) beside them.

Each robot's directory holds what a single robot's run writes (its rollout and its own
figures); ``--html`` writes ``replay.html`` beside them, drawing every robot.
Exit status as ``uvms-pin run``'s: 0 the run reached its end, 3 it stopped early (what was
simulated is saved), 130 Ctrl-C, 143 SIGTERM (handled as Ctrl-C).
"""

from __future__ import annotations

import argparse
import sys

from uvms_pin.apps.arguments import say_user_traceback
from uvms_pin.apps.exit_codes import EXIT_BAD_INPUT, EXIT_RUN_STOPPED
from uvms_pin.apps.interrupts import InterruptGuard, stop_status
from uvms_pin.errors import ParameterError, SimulationError
from uvms_pin.results.metrics import compute_metrics
from uvms_pin.results.outdir import RUN, check_writable, claim
from uvms_pin.results.progress import progress_printer
from uvms_pin.sim.robots_run import RobotsScenario, simulate_robots


def run_robots(scenario: RobotsScenario, args: argparse.Namespace) -> int:
    """Run every robot of ``scenario``, save the results into ``args.out``; the exit
    status."""
    if args.live:
        raise ParameterError("--live shows one robot: not a scenario with [[robots]]")
    out = check_writable(args.out)
    with InterruptGuard(), claim(out, RUN, overwrite=args.overwrite):
        status, message = 0, ""
        try:
            rollouts = _simulate(scenario, args.quiet)
        except SimulationError as exc:
            rollouts, status = exc.rollout, EXIT_RUN_STOPPED
            message = f"uvms-pin: run stopped: {exc}; what was simulated is kept in {out}"
        except KeyboardInterrupt as exc:  # Ctrl-C, or SIGTERM (`Terminated`)
            status, stopped = stop_status(exc)
            rollouts = getattr(exc, "rollout", None)
            message = f"uvms-pin: {stopped}; what was simulated is kept in {out}"
        if rollouts is None:
            print(message, file=sys.stderr)
            return status
        try:
            rollouts.save(out)
        except ParameterError as exc:  # a metric of yours: the run is kept, then refused
            metric_failure = exc
        else:
            metric_failure = None
        _figures(rollouts, out, args.html)
    for name, rollout in rollouts.rollouts.items():
        metrics = compute_metrics(rollout, extra=False)  # its timing
        print(
            f"scenario {scenario.name}, robot {name}: {rollout.metadata['status']}, simulated "
            f"{metrics['simulated_time_s']:.3f} s in {metrics['wall_time_s']:.2f} s"
        )
    print(f"wrote {out}/metrics.json and {', '.join(f'{out}/{n}/' for n in rollouts.names)}")
    if message:
        print(message, file=sys.stderr)
    if metric_failure is not None:
        say_user_traceback(metric_failure.user_traceback)
        print(
            f"uvms-pin: error: {metric_failure}; the run is kept in {out} (metrics.json "
            f"without your metrics: once fixed, RobotRollouts.load('{out}').metrics())",
            file=sys.stderr,
        )
        return EXIT_BAD_INPUT
    return status


def _simulate(scenario: RobotsScenario, quiet: bool):
    """The run, with the progress line of ``uvms-pin run`` unless ``quiet``."""
    if quiet:
        return simulate_robots(scenario)
    with progress_printer(scenario.name, scenario.settings.duration_s, delay_s=0.0) as printer:
        return simulate_robots(scenario, progress=printer)


def _figures(rollouts, out, html: bool) -> None:
    """Each robot's figures in its directory; with ``html``, ``replay.html`` drawing every
    robot (`uvms_pin.apps.viz.robots_replay`)."""
    from uvms_pin.apps.outputs import write_figures

    for name, rollout in rollouts.rollouts.items():
        write_figures(rollout, out / name)
    if html and len(rollouts):
        from uvms_pin.apps.viz.robots_replay import write_robots_replay

        write_robots_replay(rollouts, out / "replay.html")
