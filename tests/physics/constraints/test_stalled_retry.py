"""A constraint solve that stalls above the residual it may keep is solved once more with
the ADMM's Anderson acceleration (`step._solve_or_accelerate`): the accepted one of the
two is kept, else the smaller residual, with both solves' iterations; a solve that is
accepted at once is not retried (every other period stays as it was)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from uvms_pin.physics.constraints import step
from uvms_pin.physics.constraints.step import ANDERSON_CAPACITY, ConstrainedVelocity, StalledSolves

SPEED_M_S = 1.0  # the rows' largest speed: a stalled solve may keep 1e-4 m/s


def _result(residual: float, converged: bool, iterations: int) -> ConstrainedVelocity:
    velocity = np.full(2, residual)
    return ConstrainedVelocity(
        velocity, {}, {}, np.zeros(2), (), iterations, residual, converged, SPEED_M_S
    )


@pytest.fixture
def solves(monkeypatch):
    """`step._solve` answering from a queue, recording each call's Anderson capacity."""
    queue: list[ConstrainedVelocity] = []
    capacities: list[int] = []

    def fake(mass, v_free, blocks, h, correction, settings):
        capacities.append(int(settings.anderson_capacity))
        return queue.pop(0)

    monkeypatch.setattr(step, "_solve", fake)
    return queue, capacities


def _solve():
    settings = step.default_settings()
    return step._solve_or_accelerate(np.eye(2), np.zeros(2), (), 1e-3, 0.5, settings=settings)


def test_an_accepted_solve_is_not_retried(solves):
    queue, capacities = solves
    queue += [_result(5e-5, False, 5000)]  # stalled below 1e-4 m/s: kept
    out = _solve()
    assert capacities == [0] and out.residual == 5e-5 and out.iterations == 5000


def test_a_solve_stalled_above_its_bound_is_retried_accelerated(solves):
    queue, capacities = solves
    queue += [_result(3e-4, False, 5000), _result(1e-9, True, 461)]
    out = _solve()
    assert capacities == [0, ANDERSON_CAPACITY]
    assert out.converged and out.residual == 1e-9 and out.iterations == 5461


def test_the_smaller_residual_is_kept_when_neither_is_accepted(solves):
    queue, _ = solves
    queue += [_result(3e-4, False, 5000), _result(6e-4, False, 5000)]
    out = _solve()
    assert not out.accepted and out.residual == 3e-4 and out.iterations == 10000
    queue += [_result(6e-4, False, 5000), _result(3e-4, False, 5000)]
    assert _solve().residual == 3e-4


def test_a_runs_stalled_solves_are_counted_with_the_worst_residual():
    """`StalledSolves`: each accepted stalled solve counts once, the largest residual kept;
    merged with the compiled system's count and worst; recorded as the run's metadata."""
    stalled = StalledSolves()
    assert stalled.record()["stalled"] == 0
    for residual in (3e-6, 8e-5, 1e-6):
        stalled.add(residual)
    assert (stalled.count, stalled.worst_residual_m_s) == (3, 8e-5)
    both = stalled.merged(2, 9e-5)
    assert (both.count, both.worst_residual_m_s) == (5, 9e-5)
    assert (stalled.count, stalled.worst_residual_m_s) == (3, 8e-5)  # not changed
    assert stalled.merged(4, 1e-7).worst_residual_m_s == 8e-5
    record = stalled.record()
    assert (record["stalled"], record["worst_stalled_residual_m_s"]) == (3, 8e-5)
    assert "m/s" in record["acceptable_residual"]


def test_a_stalled_solve_may_keep_1e_4_of_its_rows_speed_and_at_least_1e_5_m_s():
    """The bound a stalled solve is accepted under: 1e-4 of |g|_inf, at least 1e-5 m/s."""

    def stalled(residual: float, speed_m_s: float) -> ConstrainedVelocity:
        return ConstrainedVelocity(
            np.zeros(2), {}, {}, np.zeros(2), (), 5000, residual, False, speed_m_s
        )

    assert stalled(0.0, 2.0).acceptable_residual == pytest.approx(2e-4, rel=1e-15)
    assert stalled(1.9e-4, 2.0).accepted and not stalled(2.1e-4, 2.0).accepted
    assert stalled(0.0, 0.01).acceptable_residual == 1e-5  # the floor
    assert stalled(9e-6, 0.01).accepted and not stalled(1.1e-5, 0.01).accepted
    converged = dataclasses.replace(stalled(1.0, 2.0), converged=True)
    assert converged.accepted  # converged: whatever its residual
