"""A batch from one scenario: ``simulate_batch(scenario, overrides_list, num_threads)``.

Each run is the base scenario (a file, or a `Scenario`) with one set of dotted overrides,
loaded afresh: its own plant, controller and seeded sensors; the runs go on threads
(`uvms_pin.sim.batch.run_batch`), each exactly as `simulate` would run it, so a batch's
rollouts are those of the single runs, bit for bit, whatever the number of threads.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from uvms_pin.checks import check_memory, thread_count
from uvms_pin.errors import ParameterError, SimulationError
from uvms_pin.results.rollout import Rollout
from uvms_pin.scenario.load import load_scenario, scenario_from_dict
from uvms_pin.sim.batch import run_batch
from uvms_pin.sim.run import Scenario


def scenario_for(base: Scenario | str | Path, overrides: Mapping[str, Any]) -> Scenario:
    """A fresh scenario: ``base`` (a file, or a `Scenario`) with ``overrides`` (dotted keys)."""
    if not isinstance(base, Scenario):
        return load_scenario(base, dict(overrides))
    if not overrides:
        return copy.deepcopy(base)  # its own plant and sensors: runs never share state
    return scenario_from_dict(base.raw, base.path, dict(overrides))


#: what a run of a batch holds besides its log [bytes]: its own scenario (plant, model data,
#: controller, sensors), 0.5 MiB measured on the shipped ones (a deep copy), counted twice
RUN_OVERHEAD_BYTES = 2**20


def _check_batch_fits(base: Scenario, runs: int) -> None:
    """ParameterError before any run is built if ``runs`` of ``base`` (their scenarios and
    their logs, all kept until the batch returns) would take more than half of the memory
    available. Runs whose overrides lengthen them are not in this estimate: each is checked
    on its own when it is built."""
    uvms, settings = base.uvms, base.settings
    each = settings.log_bytes(uvms.nq, uvms.nv) + RUN_OVERHEAD_BYTES
    check_memory(
        runs * each,
        f"a batch of {runs} runs (each its own scenario and a log of {settings.n_log} samples)",
        "run fewer at once (split overrides_list), or shorten scenario.duration_s or lengthen "
        "output.log_period_s",
    )


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
    thread_count(num_threads)
    if isinstance(overrides_list, Mapping) or not isinstance(overrides_list, Sequence):
        raise ParameterError(
            f"overrides_list must be a list of dicts, got {type(overrides_list).__name__}"
        )
    base = scenario if isinstance(scenario, Scenario) else load_scenario(scenario)
    _check_batch_fits(base, len(overrides_list))
    for k, overrides in enumerate(overrides_list):
        if not isinstance(overrides, Mapping):
            raise ParameterError(
                f"overrides_list[{k}] must be a dict of dotted keys, got {type(overrides).__name__}"
            )
    scenarios = [scenario_for(scenario, o) for o in overrides_list]
    runs = run_batch(scenarios, num_threads, compiled_loop=compiled_loop)
    for run in runs:  # a bad input or a bug is not a result: raised (the first)
        if run.error is not None and not isinstance(run.error, SimulationError):
            raise run.error
    return [run.rollout for run in runs]
