"""Several runs at once on threads: ``run_batch(scenarios, num_threads)``.

Each run is a scenario of its own (its own plant, controller and seeded sensors), simulated
exactly as `simulate` would, so a batch's rollouts are those of the single runs, bit for
bit, whatever the number of threads (`uvms_pin.scenario.batch.simulate_batch` makes the
scenarios from one base and a list of overrides). The runs overlap where the GIL is
released: in the compiled closed loop (`uvms_pin.sim.compiled_loop`), one chunk of ticks per
call; a run on the Python loop holds the GIL and the threads then take turns.

Studies (``uvms-pin sweep``) batch the runs of a worker this way; Dask spreads the workers
over processes and machines.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

from uvms_pin.checks import thread_count
from uvms_pin.results.robots import RobotRollouts
from uvms_pin.results.rollout import Rollout
from uvms_pin.sim.robots_run import RobotsScenario, simulate_robots
from uvms_pin.sim.run import Scenario, simulate


@dataclass
class BatchRun:
    """One run of a batch: its rollout (partial when it stopped early; None if it never
    started) and what stopped it (a `SimulationError`, e.g. a `FunnelViolation`, a
    KeyboardInterrupt, or any other exception the run raised; None for a run that
    finished)."""

    rollout: Rollout | RobotRollouts | None
    error: BaseException | None = None
    wall_s: float = 0.0  # the run's own wall time (others ran meanwhile)


def run_batch(
    scenarios: Sequence[Scenario | RobotsScenario],
    num_threads: int | None = None,
    *,
    compiled_loop: bool = True,
) -> list[BatchRun]:
    """Simulate each of ``scenarios`` (each used by one run only; a scenario of several
    robots by `simulate_robots`, its rollout a `RobotRollouts`) on ``num_threads`` threads
    (default: the CPU count); one `BatchRun` per scenario, in order. Ctrl-C stops every run at
    its next logged sample (each keeps its partial rollout) and is raised again, with the
    batch's runs as ``exc.runs``."""
    threads = thread_count(num_threads)
    stop = threading.Event()

    def one(scenario: Scenario) -> BatchRun:
        def progress(time_s: float, duration_s: float) -> None:
            if stop.is_set():
                raise KeyboardInterrupt

        start = time.perf_counter()
        try:
            if isinstance(scenario, RobotsScenario):  # several robots: their own run
                rollout = simulate_robots(scenario, progress=progress)
            else:
                rollout = simulate(scenario, progress=progress, compiled_loop=compiled_loop)
            return BatchRun(rollout, None, time.perf_counter() - start)
        except (Exception, KeyboardInterrupt) as exc:  # the run's outcome, kept with the others'
            return BatchRun(getattr(exc, "rollout", None), exc, time.perf_counter() - start)

    with ThreadPoolExecutor(max_workers=threads, thread_name_prefix="uvms-batch") as pool:
        futures = [pool.submit(one, s) for s in scenarios]
        try:
            return [f.result() for f in futures]
        except KeyboardInterrupt as exc:
            stop.set()
            for f in futures:
                f.cancel()
            exc.runs = [f.result() if not f.cancelled() else BatchRun(None, exc) for f in futures]
            raise
