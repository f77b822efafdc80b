"""The runs of a study as they execute on a worker: a row per run, never an exception.

A worker's task is a few runs (`RUNS_PER_TASK`): their scenarios are loaded one by one and
simulated together on threads (`uvms_pin.sim.batch.run_batch`; the compiled closed loop
releases the GIL), each exactly as alone. Dask spreads the tasks over the worker processes
and machines (`uvms_pin.apps.study.runner`).
"""

from __future__ import annotations

import json
import math
import socket
import time
import traceback
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from uvms_pin.apps.study.spec import Run
from uvms_pin.errors import ControllerError, FunnelViolation, ParameterError, SimulationError
from uvms_pin.results.metrics import checked_metrics
from uvms_pin.results.robots import RobotRollouts
from uvms_pin.sim.robots_run import RobotsScenario

#: Runs per Dask task: fewer tasks to schedule, runs of a task overlapping on threads.
RUNS_PER_TASK = 4


def execute_run(base: str, run: Run, rollout_dir: str | None = None) -> dict[str, Any]:
    """Load the base scenario with the run's overrides, scale the plant, simulate; a row.

    Never raises for a failed run: the status and message go in the row.
    """
    return execute_runs(base, [run], rollout_dir)[0]


def execute_runs(
    base: str, runs: list[Run], rollout_dir: str | None = None, num_threads: int = 1
) -> list[dict[str, Any]]:
    """`execute_run` of each of ``runs``, simulated together on ``num_threads`` threads;
    the rows in order (each the row of the run alone, its wall time its load plus its
    simulation)."""

    def load(row: dict[str, Any], run: Run):
        scenario = _scenario(base, run)
        for prefix, robot in _robots(scenario):
            row[f"{prefix}net_buoyancy_N"] = robot.uvms.net_buoyancy_N
        return scenario

    def fill(row: dict[str, Any], scenario, outcome, run: Run) -> None:
        _outcome_into(row, outcome, run, rollout_dir)

    return batch_rows(runs, load, fill, num_threads)


def batch_rows(
    runs: list[Run],
    load: Callable[[dict[str, Any], Run], Any],
    fill: Callable[[dict[str, Any], Any, Any, Run], None],
    num_threads: int = 1,
) -> list[dict[str, Any]]:
    """A row per run (`base_row`), never an exception: each run's scenario loaded by
    ``load(row, run)`` (which may add to the row), then all simulated together on
    ``num_threads`` threads (`uvms_pin.sim.batch.run_batch`) and each outcome put in its row
    by ``fill(row, scenario, outcome, run)``; a run that raises in either is an "error" row with its
    traceback. ``run_wall_time_s``: the run's load plus its simulation [s]."""
    from uvms_pin.sim.batch import run_batch

    rows, scenarios, loaded, wall_s = [], [], [], []
    for run in runs:
        start = time.perf_counter()
        rows.append(base_row(run))
        try:
            scenarios.append(load(rows[-1], run))
            loaded.append(len(rows) - 1)
        except Exception as exc:  # a bad input in one run must not stop the others
            _failed(rows[-1], exc)
        wall_s.append(time.perf_counter() - start)
    outcomes = run_batch(scenarios, num_threads)
    for k, scenario, outcome in zip(loaded, scenarios, outcomes, strict=True):
        try:
            fill(rows[k], scenario, outcome, runs[k])
        except Exception as exc:
            _failed(rows[k], exc)
        wall_s[k] += outcome.wall_s
    for row, seconds in zip(rows, wall_s, strict=True):
        row["run_wall_time_s"] = seconds
    return rows


def _scenario(base: str, run: Run):
    from uvms_pin.apps.study.plant import modify_plant
    from uvms_pin.scenario.load import load_scenario

    return modify_plant(load_scenario(base, run.overrides), run.plant)


def _failed(row: dict[str, Any], exc: BaseException) -> None:
    row.update(status="error", error=f"{type(exc).__name__}: {exc}")
    row["traceback"] = "".join(traceback.format_exception(exc, limit=8))


def _outcome_into(row: dict[str, Any], outcome, run: Run, rollout_dir: str | None) -> None:
    """The run's status, violation and metrics into ``row``; its rollout saved if asked."""
    exc, rollout = outcome.error, outcome.rollout
    if isinstance(exc, FunnelViolation):
        row.update(
            status="FunnelViolation",
            error=str(exc),
            violation_level=exc.level,
            violation_component=exc.component,
            violation_time_s=float(exc.time_s),
        )
    elif isinstance(exc, ControllerError):  # the controller raised: not a result, an error
        row.update(status="error", error=str(exc))
        cause = exc.__cause__
        row["traceback"] = exc.user_traceback or "".join(
            traceback.format_exception(cause, limit=8) if cause else ()
        )
    elif isinstance(exc, SimulationError):
        row.update(status="diverged", error=str(exc))
    elif isinstance(exc, KeyboardInterrupt):
        raise exc
    elif exc is not None:  # a bug or a bad input in one run must not stop the study
        _failed(row, exc)
    # a metric of your own that fails: the row keeps the built-in ones and says "error"
    # (`--retry-errors` runs it again once fixed), the rollout is saved as asked
    failures = []
    if isinstance(rollout, RobotRollouts):  # several robots: each one's columns, "name/..."
        for name in rollout.names:
            robot = rollout.robot(name)
            metrics, failure = checked_metrics(robot)
            row.update(_prefixed(f"{name}/", {**rollout_quantities(robot), **metrics}))
            failures += [failure] if failure is not None else []
        for name, metrics in rollout.object_metrics().items():
            row.update(_prefixed(f"{name}/", metrics))
    elif rollout is not None:
        metrics, failure = checked_metrics(rollout)
        row.update({**rollout_quantities(rollout), **metrics})
        failures += [failure] if failure is not None else []
    if failures and exc is None:
        _failed(row, failures[0])
    elif failures:  # the run's own ending stays its status; your metric's failure is said too
        row["error"] = f"{row.get('error') or ''}; {failures[0]}".lstrip("; ")
    if rollout is not None and rollout_dir is not None:
        try:
            rollout.save(Path(rollout_dir) / run.run_id)
        except ParameterError:  # several robots' save: your metric, already in the row
            pass


def _robots(scenario) -> list[tuple[str, Any]]:
    """(column prefix, scenario) of each robot: "" for a single robot's scenario, "name/"
    for each of several robots'."""
    if isinstance(scenario, RobotsScenario):
        return [(f"{n}/", r) for n, r in zip(scenario.names, scenario.robots, strict=True)]
    return [("", scenario)]


def _prefixed(prefix: str, values: dict[str, Any]) -> dict[str, Any]:
    return {f"{prefix}{k}": v for k, v in values.items()}


def base_row(run: Run) -> dict[str, Any]:
    """The columns every row has, whatever happened to the run."""
    row: dict[str, Any] = {
        "run_id": run.run_id,
        "run_index": run.index,
        "sample": run.sample,
        "seed": run.seed,
        "status": "ok",
        "error": "",
        "violation_level": "",
        "violation_component": "",
        "violation_time_s": math.nan,
        "host": socket.gethostname(),
    }
    for path, value in run.values.items():
        row[run.columns.get(path, path)] = (
            value if not isinstance(value, list) else json.dumps(value)
        )
    return row


def rollout_quantities(rollout) -> dict[str, float]:
    """Initial orientation error, and how often the actuators saturated."""
    out: dict[str, float] = {}
    s = rollout.signals
    if "e_x" in s and len(s["e_x"]):
        e_o = s["e_x"][0, 3:6]
        for name, value in zip(("roll", "pitch", "yaw"), e_o, strict=True):
            out[f"initial_error_{name}_rad"] = float(value)
        out["initial_orientation_error_max_rad"] = float(np.max(np.abs(e_o)))
    if "xi_x" in s and len(s["xi_x"]):
        out["initial_orientation_xi_max"] = float(np.max(np.abs(s["xi_x"][0, 3:6])))
    commanded = s.get("tau_commanded")
    if commanded is not None and len(commanded):
        clipped = np.abs(commanded - rollout.tau) > 1e-6 * np.maximum(1.0, np.abs(commanded))
        # surge, sway, heave, yaw: roll and pitch may be unactuated (always "clipped")
        out["vehicle_saturation_fraction"] = float(
            np.mean(np.any(clipped[:, [0, 1, 2, 5]], axis=1))
        )
        out["joint_saturation_fraction"] = float(np.mean(np.any(clipped[:, 6:], axis=1)))
    return out


def error_row(run: Run, exc: BaseException) -> dict[str, Any]:
    """The row of a run whose task itself failed (worker killed, unpicklable result...)."""
    row = base_row(run)
    row.update(status="error", error=f"{type(exc).__name__}: {exc}", host="")
    return row
