"""``uvms-pin run``: simulate a scenario, save what was simulated, say how it ended.

Whatever ends the run (its end, a funnel violation, a divergence, the controller raising,
Ctrl-C), what was simulated is saved first (rollout.npz, rollout.json, metrics.json, under
`InterruptGuard.saving`: a second Ctrl-C does not cut it), then the figures (a Ctrl-C
stops them between two figures). Exit status:
0 the run reached its end; 3 it stopped early (the rollout kept); 130 Ctrl-C, 143 SIGTERM (a
batch system's time limit: handled as Ctrl-C, the rollout kept); 4 the
system failed us while saving (a full disk...), the message naming the file and what was
kept.
"""

from __future__ import annotations

import argparse
import sys
from contextlib import nullcontext
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from uvms_pin.apps.arguments import say_user_traceback
from uvms_pin.apps.exit_codes import EXIT_BAD_INPUT, EXIT_ENVIRONMENT, EXIT_RUN_STOPPED
from uvms_pin.apps.interrupts import InterruptGuard, stop_status
from uvms_pin.errors import ParameterError, SimulationError
from uvms_pin.results.outdir import RUN, check_writable, claim
from uvms_pin.results.progress import progress_printer
from uvms_pin.scenario.overrides import parse_assignment

if TYPE_CHECKING:
    from uvms_pin.results.rollout import Rollout


@dataclass
class Ending:
    """How a run ended, for the command's output: its rollout (None: nothing simulated),
    the exit status and what to say; ``user_traceback``: the frames of the user's code
    that stopped it."""

    rollout: Rollout | None
    status: int = 0
    message: str = ""
    user_traceback: str = ""


#: the live viewers (``--live NAME``) and the port each listens on by default
LIVE_PORTS = {"meshcat": 7000, "foxglove": 8765}


def check_view_options(args: argparse.Namespace) -> None:
    """--port in range (run, replay); without --port, the live viewer's own default."""
    if args.port is None:
        args.port = LIVE_PORTS.get(args.live or "meshcat")
    if not 0 <= args.port <= 65535:
        raise ParameterError(f"--port must be in 0..65535, got {args.port}")


def cmd_run(args: argparse.Namespace) -> int:
    from threadpoolctl import threadpool_limits

    # A run is one thread of small numpy operations (a control tick's vectors and matrices):
    # BLAS worker threads never speed them up, but an operation large enough wakes them and
    # they spin a while after it, taking a core from the run (and CPU time from the process)
    with threadpool_limits(limits=1, user_api="blas"):
        return _run(args)


def _run(args: argparse.Namespace) -> int:
    from uvms_pin.scenario.load import load_scenario
    from uvms_pin.sim.run import Scenario

    check_view_options(args)
    overrides = dict(parse_assignment(text) for text in args.set)
    if args.no_code:
        _check_no_code(args.scenario, overrides)
    scenario = load_scenario(args.scenario, overrides)
    if not isinstance(scenario, Scenario):  # [[robots]]: several robots
        from uvms_pin.apps.cli.run_robots import run_robots

        return run_robots(scenario, args)
    out = check_writable(args.out)  # before simulating, not after
    with InterruptGuard() as guard, claim(out, RUN, overwrite=args.overwrite):
        ending = _simulate_to_end(scenario, args)
        say_user_traceback(ending.user_traceback, "the run stopped in your controller's code")
        if ending.rollout is None:
            print(ending.message, file=sys.stderr)
            return ending.status
        written, failure = _save(ending, out, args, guard)
    _report(scenario.name, ending, out, written)
    if ending.status and (failure is None or _rollout_saved(written)):
        # the run's own ending (interrupted, stopped): true once its rollout is on disk,
        # whatever then cut the figures
        print(ending.message, file=sys.stderr)
    if failure is not None:
        say_user_traceback(failure.user_traceback)
        print(failure.message, file=sys.stderr)
        return failure.status
    return ending.status


def _check_no_code(scenario_file: str, overrides: dict) -> None:
    """--no-code: the file (with its overrides) refused before anything is imported or read
    beyond it (`uvms_pin.scenario.trust`)."""
    from uvms_pin.errors import ScenarioError
    from uvms_pin.scenario.overrides import apply_overrides
    from uvms_pin.scenario.toml import read_toml
    from uvms_pin.scenario.trust import check_no_code

    path = Path(scenario_file)
    check_no_code(apply_overrides(read_toml(path, ScenarioError), overrides), path)


def _simulate(scenario, args: argparse.Namespace, progress) -> Rollout:
    from uvms_pin.sim.run import simulate

    if not args.live:
        return simulate(scenario, progress=progress)
    view = {"port": args.port, "speed": args.speed, "progress": progress, "out": sys.stdout}
    if args.live == "foxglove":  # Foxglove draws the bag's markers, not the URDF geometry
        from uvms_pin.apps.viz.foxglove_live import run_foxglove

        return run_foxglove(scenario, **view)
    from uvms_pin.apps.viz.live import run_live

    return run_live(scenario, show=args.show, **view)


def _simulate_to_end(scenario, args: argparse.Namespace) -> Ending:
    """The run's `Ending`: a stopped or interrupted run keeps its rollout."""
    duration_s = scenario.settings.duration_s
    printer = (
        nullcontext() if args.quiet else progress_printer(scenario.name, duration_s, delay_s=0.0)
    )
    with printer as progress:
        return _run_or_stop(scenario, args, progress)


def _run_or_stop(scenario, args: argparse.Namespace, progress) -> Ending:
    try:
        return Ending(_simulate(scenario, args, progress))
    except SimulationError as exc:  # FunnelViolation, ControllerError included
        rollout = getattr(exc, "rollout", None)
        return Ending(
            rollout,
            EXIT_RUN_STOPPED,
            f"uvms-pin: run stopped: {exc}; {_kept(rollout, args.out)}",
            exc.user_traceback,
        )
    except KeyboardInterrupt as exc:  # Ctrl-C, or SIGTERM (`Terminated`)
        status, stopped = stop_status(exc)
        rollout = getattr(exc, "rollout", None)
        if rollout is None or not len(rollout):
            return Ending(None, status, f"uvms-pin: {stopped} before the first sample")
        return Ending(rollout, status, f"uvms-pin: {stopped}: {_kept(rollout, args.out)}")


def _kept(rollout: Rollout | None, out: str) -> str:
    """``the partial rollout (t = 0 to T s) is kept in OUT`` (what was simulated)."""
    if rollout is None:
        return "nothing was simulated"
    if not len(rollout):
        return f"nothing was simulated (the rollout saved in {out} says why, and is empty)"
    t_s = float(rollout.time_s[-1])
    return f"the partial rollout (t = 0 to {t_s:.3f} s) is kept in {out}"


def _save(
    ending: Ending, out: Path, args: argparse.Namespace, guard: InterruptGuard
) -> tuple[list[str], Ending | None]:
    """(the file names written, a failure to report or None): the rollout and metrics.json
    whole or not at all, then the figures (and replay.html)."""
    from uvms_pin.apps.outputs import write_figures, write_results

    rollout = ending.rollout
    try:
        with guard.saving():
            metric_failure = write_results(rollout, out)
        guard.release()
        write_figures(rollout, out, guard.checkpoint)
        if args.html:
            from uvms_pin.apps.viz.replay import write_replay

            write_replay(rollout, out / "replay.html", show=args.show)
        guard.checkpoint()  # a Ctrl-C during the replay: the command says it stopped
        if metric_failure is not None:  # your metric's input error, the run kept
            written = _files_of_the_run(out)
            return written, Ending(
                rollout,
                EXIT_BAD_INPUT,
                f"uvms-pin: error: {metric_failure}; kept in {out}: {', '.join(written)} "
                f"(metrics.json without your metrics: once fixed, "
                f"Rollout.load('{out}').metrics())",
                metric_failure.user_traceback,
            )
    except KeyboardInterrupt as exc:
        status, stopped = stop_status(exc)
        written = _files_of_the_run(out)
        kept = ", ".join(written) or "nothing"
        return written, Ending(
            rollout, status, f"uvms-pin: {stopped} while saving; kept in {out}: {kept}"
        )
    except OSError as exc:  # a full disk, a directory removed meanwhile (ResourceError too)
        written = _files_of_the_run(out)
        return written, Ending(rollout, EXIT_ENVIRONMENT, _write_failure(exc, out, written))
    return _files_of_the_run(out), None


def _rollout_saved(written: list[str]) -> bool:
    """Whether ``written`` holds the whole rollout and its metrics (`write_results`)."""
    from uvms_pin.apps.outputs import RESULT_FILES

    return set(RESULT_FILES) <= set(written)


def _files_of_the_run(out: Path) -> list[str]:
    """The run's files in ``out`` (`claim` left none of an earlier run's there)."""
    return [name for name in RUN.patterns if (out / name).is_file()]


def _write_failure(exc: OSError, out: Path, written: list[str]) -> str:
    """What could not be written and what was kept (the run itself went as reported)."""
    where = exc.filename or out
    kept = (
        f"kept in {out}: {', '.join(written)}"
        if written
        else f"nothing of this run was kept in {out}"
    )
    return f"uvms-pin: error: cannot write {where}: {exc.strerror or exc}; {kept}"


def _shortened_note(rollout: Rollout) -> str:
    """What the run line adds for a run `UVMS_PIN_MAX_DURATION_S` shortened."""
    own_s = rollout.metadata.get("shortened_from_s")
    if own_s is None:
        return ""
    from uvms_pin.sim.shortened import MAX_DURATION_ENV

    return f", SHORTENED from {own_s:g} s by {MAX_DURATION_ENV}"


def _report(name: str, ending: Ending, out: Path, written: list[str]) -> None:
    """The run's line (status, simulated and wall time) and the files written."""
    from uvms_pin.results.metrics import compute_metrics

    rollout = ending.rollout
    metrics = compute_metrics(rollout, extra=False)  # its timing (yours were saved or said)
    print(
        f"scenario {name}: {rollout.metadata['status']}, simulated "
        f"{metrics['simulated_time_s']:.3f} s in {metrics['wall_time_s']:.2f} s "
        f"(real-time factor {metrics['real_time_factor']:.2f})" + _shortened_note(rollout)
    )
    if not written:
        return
    line = f"wrote {out}/{written[0]}" + "".join(f", {n}" for n in written[1:])
    if len(rollout) < 2:
        samples = "one" if len(rollout) == 1 else "none"
        line += f"; no figures (a figure needs two samples, the run has {samples})"
    print(line)
