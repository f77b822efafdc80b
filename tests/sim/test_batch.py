"""simulate_batch: several runs on threads, each the single run bit for bit."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT

import uvms_pin as up
from uvms_pin.errors import ParameterError, ScenarioError
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.batch import run_batch

REALISTIC = ROOT / "scenarios" / "realistic_force_tracking.toml"
OVERRIDES = [
    {"scenario.duration_s": 0.3},
    {"scenario.duration_s": 0.3, "environment.stiffness_N_m": [50.0, 50.0, 50.0]},
    {"scenario.duration_s": 0.3, "scenario.seed": 7, "disturbance.period_s": 2.0},
    # the paper's k_zeta at 500 Hz: stops early with a funnel violation
    {"scenario.duration_s": 0.3, "controller.k_zeta": 5.0},
]


def _same(a, b):
    assert len(a) == len(b)
    for name in ("time_s", "q", "v", "tau", "wrench_measured_world", "kinetic_energy_J"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert list(a.signals) == list(b.signals)
    for name, values in b.signals.items():
        np.testing.assert_array_equal(a.signals[name], values, err_msg=name)
    assert a.status == b.status


def _single(overrides):
    try:
        return up.simulate(load_scenario(REALISTIC, overrides), progress=False)
    except up.SimulationError as exc:
        return exc.rollout


@pytest.mark.parametrize("threads", [1, 2, 3])
def test_a_batch_is_its_single_runs_bit_for_bit(threads):
    singles = [_single(o) for o in OVERRIDES]
    batch = up.simulate_batch(REALISTIC, OVERRIDES, num_threads=threads)
    assert len(batch) == len(OVERRIDES)
    for single, batched in zip(singles, batch, strict=True):
        _same(batched, single)
    assert batch[3].status.kind == "FunnelViolation" and batch[0].status.ok
    assert batch[0].metadata["closed_loop"]["path"] == "compiled"
    # different stiffness, different run: the comparison above can fail
    assert not np.array_equal(batch[0].wrench_contact_world, batch[1].wrench_contact_world)


def test_a_batch_of_a_scenario_object_and_its_errors():
    scenario = load_scenario(REALISTIC, {"scenario.duration_s": 0.2})
    batch = up.simulate_batch(scenario, [{}, {}], num_threads=2)
    _same(batch[0], batch[1])
    _same(batch[0], up.simulate(scenario, progress=False))
    runs = run_batch([load_scenario(REALISTIC, OVERRIDES[3])], 1)
    assert isinstance(runs[0].error, up.FunnelViolation) and runs[0].rollout is not None
    with pytest.raises(ParameterError, match="num_threads"):
        up.simulate_batch(REALISTIC, [{}], num_threads=0)
    with pytest.raises(ParameterError, match="overrides_list"):
        up.simulate_batch(REALISTIC, {"scenario.duration_s": 1.0})
    with pytest.raises(ScenarioError, match="nope"):
        up.simulate_batch(REALISTIC, [{"scenario.nope": 1}])


def test_a_batch_too_large_for_memory_is_refused_before_any_run_is_built(monkeypatch):
    """Every run keeps its own scenario and log until the batch returns: 100 runs of the
    realistic scenario (a 1.7 MB log and about 1 MiB of its own each) in 64 MiB are refused
    from the count, before the first is built (a batch of [{}] * 100000 used to deep-copy
    its scenarios until the machine ran out of memory)."""
    import uvms_pin.checks as checks
    import uvms_pin.scenario.batch as batch

    monkeypatch.setattr(checks, "available_memory_bytes", lambda: 64 * 2**20)
    monkeypatch.setattr(batch, "scenario_for", lambda *a: pytest.fail("a run was built"))
    with pytest.raises(ParameterError, match=r"a batch of 100 runs .*split overrides_list"):
        up.simulate_batch(REALISTIC, [{}] * 100)
    base = load_scenario(REALISTIC)
    batch._check_batch_fits(base, 10)  # 27 MB: within half of the 64 MiB
    with pytest.raises(ParameterError, match="a batch of 13 runs"):
        batch._check_batch_fits(base, 13)  # 35 MB: beyond it
