"""Several runs at once on threads: ``simulate_batch(scenario, overrides_list, num_threads)``.

Each run is a scenario of its own (the base scenario with one set of overrides, loaded
afresh: its own plant, controller and seeded sensors), simulated exactly as `simulate` would,
so a batch's rollouts are those of the single runs, bit for bit, whatever the number of
threads. The runs overlap where the GIL is released: in the compiled closed loop
(`uvms_pin.sim.compiled_loop`), one chunk of ticks per call; a run on the Python loop holds
the GIL and the threads then take turns.

Studies (``uvms-pin sweep``) batch the runs of a worker this way; Dask spreads the workers
over processes and machines.
"""

from __future__ import annotations

import copy
import importlib
import os
import threading
import time
from collections.abc import Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from uvms_pin.errors import ParameterError, SimulationError
from uvms_pin.results.rollout import Rollout
from uvms_pin.sim.run import Scenario, simulate


@dataclass
class BatchRun:
    """One run of a batch: its rollout (partial when it stopped early; None if it never
    started) and what stopped it (a `SimulationError`, e.g. a `FunnelViolation`, a
    KeyboardInterrupt, or any other exception the run raised; None for a run that
    finished)."""

    rollout: Rollout | None
    error: BaseException | None = None
    wall_s: float = 0.0  # the run's own wall time (others ran meanwhile)


def _scenario_for(base: Scenario | str | Path, overrides: Mapping[str, Any]) -> Scenario:
    """A fresh scenario: ``base`` (a file, or a `Scenario`) with ``overrides`` (dotted keys)."""
    if not isinstance(base, Scenario):
        reader = importlib.import_module("uvms_pin.scenario.load")  # the layer above
        return reader.load_scenario(base, dict(overrides))
    if not overrides:
        return copy.deepcopy(base)  # its own plant and sensors: runs never share state
    return Scenario.from_dict(base.raw, base.path, dict(overrides))


def run_batch(
    scenarios: Sequence[Scenario], num_threads: int | None = None, *, compiled_loop: bool = True
) -> list[BatchRun]:
    """Simulate each of ``scenarios`` (each used by one run only) on ``num_threads`` threads
    (default: the CPU count); one `BatchRun` per scenario, in order. Ctrl-C stops every run at
    its next logged sample (each keeps its partial rollout) and is raised again, with the
    batch's runs as ``exc.runs``."""
    threads = _thread_count(num_threads)
    stop = threading.Event()

    def one(scenario: Scenario) -> BatchRun:
        def progress(time_s: float, duration_s: float) -> None:
            if stop.is_set():
                raise KeyboardInterrupt

        start = time.perf_counter()
        try:
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


def simulate_batch(
    scenario: Scenario | str | Path,
    overrides_list: Sequence[Mapping[str, Any]],
    num_threads: int | None = None,
    *,
    compiled_loop: bool = True,
) -> list[Rollout]:
    """Run ``scenario`` (a `Scenario` or a scenario file) once per entry of
    ``overrides_list`` (dotted keys as ``uvms-pin run --set``: ``{"environment.stiffness_N_m":
    [20, 20, 20]}``; ``{}`` the scenario as it is), on ``num_threads`` threads (default: the
    CPU count). Each rollout is the one `simulate` gives for that run, bit for bit, whatever
    the number of threads.

    Returns the rollouts in order; a run the simulator stopped (a funnel violation, a
    divergence) gives its partial rollout, whose ``status`` says when and why (not an
    exception: the other runs' results are kept). Use `run_batch` for the exceptions.

    Raises:
        ScenarioError: a bad override (before any run starts).
        ParameterError: ``num_threads`` not a positive integer.
        KeyboardInterrupt: Ctrl-C (every run stopped; ``exc.runs`` holds their `BatchRun`).
    """
    _thread_count(num_threads)
    if isinstance(overrides_list, Mapping) or not isinstance(overrides_list, Sequence):
        raise ParameterError(
            f"overrides_list must be a list of dicts, got {type(overrides_list).__name__}"
        )
    for k, overrides in enumerate(overrides_list):
        if not isinstance(overrides, Mapping):
            raise ParameterError(
                f"overrides_list[{k}] must be a dict of dotted keys, got {type(overrides).__name__}"
            )
    scenarios = [_scenario_for(scenario, o) for o in overrides_list]
    runs = run_batch(scenarios, num_threads, compiled_loop=compiled_loop)
    for run in runs:  # a bad input or a bug is not a result: raised (the first)
        if run.error is not None and not isinstance(run.error, SimulationError):
            raise run.error
    return [run.rollout for run in runs]


def _thread_count(num_threads: int | None) -> int:
    if num_threads is None:
        return os.cpu_count() or 1
    if isinstance(num_threads, bool) or not isinstance(num_threads, int) or num_threads < 1:
        raise ParameterError(f"num_threads must be a positive integer, got {num_threads!r}")
    return num_threads
