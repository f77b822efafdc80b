"""Run one scenario's task with each controller and collect the comparison's rows."""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from uvms_pin.apps.compare.metrics import COLUMNS, Criteria, comparison_row
from uvms_pin.apps.compare.tracking import TRACKING_COLUMNS, tracking_row
from uvms_pin.checks import check_memory
from uvms_pin.errors import FunnelViolation, ScenarioError, SimulationError
from uvms_pin.results.rollout import Rollout
from uvms_pin.scenario.baselines import baseline_controller_table, comparable_controllers
from uvms_pin.scenario.load import scenario_from_dict
from uvms_pin.scenario.overrides import apply_overrides
from uvms_pin.scenario.toml import read_toml
from uvms_pin.sim.batch import BatchRun, run_batch
from uvms_pin.sim.run import Scenario, simulate
from uvms_pin.sim.system import System

__all__ = ["batch_run_row", "compare_controllers", "controller_scenarios", "run_controller"]


def controller_scenarios(
    path: str | Path, controllers: list[str] | None, overrides: dict[str, Any] | None = None
) -> dict[str, Scenario]:
    """The scenario at ``path`` once per controller (its [controller] replaced by
    `baseline_controller_table`), every one built and checked before any run; ``None``:
    the scenario's `comparable_controllers`.

    Raises:
        ScenarioError: a bad file, override or controller name.
    """
    path = Path(path)
    # overrides first: they may set a baseline's tuning ("baselines.pi_force.damping=...")
    raw = apply_overrides(read_toml(path, ScenarioError), overrides)
    out = {}
    for name in comparable_controllers(raw) if controllers is None else controllers:
        # the controller table that runs; the other tunings are not this run's
        variant = {k: v for k, v in raw.items() if k != "baselines"}
        variant["controller"] = baseline_controller_table(raw, name)
        try:
            out[name] = scenario_from_dict(variant, path)
        except ScenarioError as exc:
            raise ScenarioError(f"controller '{name}' ([baselines.{name}]): {exc}") from exc
    first = next(iter(out.values()), None)
    if first is not None and first.task is None and first.plant.contact is None:
        raise ScenarioError(
            f"{path}: compare-controllers compares a force task (an [environment] and a "
            "desired force) or a tracking [task]; this scenario has neither"
        )
    # every controller's rollout is kept until the figures are drawn: all of them must fit
    check_memory(
        sum(
            s.settings.log_bytes(s.uvms.nq, s.uvms.nv, System(s.plant).log.n_columns)
            for s in out.values()
        ),
        f"the logs of the {len(out)} runs ({next(iter(out.values())).settings.n_log} samples each)",
        "shorten scenario.duration_s, lengthen output.log_period_s or compare fewer controllers",
        ScenarioError,
    )
    return out


def run_controller(name: str, scenario: Scenario, criteria: Criteria) -> tuple[dict, Rollout]:
    """(row, rollout) of one controller; a run the simulator stops is a row, not an error.
    On a tracking task (``scenario.task``) the row is `tracking_row`'s."""
    try:
        rollout, stopped = simulate(scenario, progress=False), ""
    except (FunnelViolation, SimulationError) as exc:
        rollout, stopped = getattr(exc, "rollout", None), f"run stopped: {exc}"
    return _row(name, scenario, rollout, stopped, criteria)


def _row(name, scenario, rollout, stopped: str, criteria: Criteria) -> tuple[dict, Rollout | None]:
    """(row, rollout) of a controller's run, ``stopped`` saying why it stopped early; a run
    stopped before its first sample (the controller cannot start there: a baseline's Euler
    angles at a tool pointing straight down) is a row without numbers and no rollout: the
    others are still compared."""
    columns = COLUMNS if scenario.task is None else TRACKING_COLUMNS
    if rollout is None or len(rollout) == 0:
        row = dict.fromkeys(columns, math.nan)
        reason = f"{stopped or 'run stopped'} (before its first sample)"
        row.update(controller=name, status="stopped", success=False, reason=reason)
        return row, None
    if scenario.task is not None:
        return tracking_row(name, rollout, scenario.plant.actuation, stopped), rollout
    return comparison_row(name, rollout, scenario.plant.actuation, criteria, stopped), rollout


def compare_controllers(
    scenarios: dict[str, Scenario],
    criteria: Criteria,
    progress: Callable[[str], None] | None = None,
) -> tuple[list[dict], dict[str, Rollout]]:
    """Rows (in the given order) and rollouts (of those that ran) of every controller's run,
    the runs side by side on threads (`uvms_pin.sim.batch.run_batch`: each the run alone, bit for bit)."""
    if progress is not None:
        progress(f"running {', '.join(scenarios)} ...")
    runs = run_batch(list(scenarios.values()), min(len(scenarios), os.cpu_count() or 1) or 1)
    rows, rollouts = [], {}
    for (name, scenario), run in zip(scenarios.items(), runs, strict=True):
        row, rollout = batch_run_row(name, scenario, run, criteria)
        rows.append(row)
        if rollout is not None:  # one that never ran has no curve to draw
            rollouts[name] = rollout
    return rows, rollouts


def batch_run_row(name: str, scenario: Scenario, run: BatchRun, criteria: Criteria):
    """(row, rollout) of a controller's run of a batch (`run_controller`'s, the run done by
    `run_batch`); its exception raised again when it is a bug or a bad input, not a result."""
    if run.error is not None and not isinstance(run.error, SimulationError):
        raise run.error
    stopped = "" if run.error is None else f"run stopped: {run.error}"
    return _row(name, scenario, run.rollout, stopped, criteria)
