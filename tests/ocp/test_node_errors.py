"""An error raised in a node while a solver runs (a user's cost term, Ctrl-C) reaches the
caller of `problems.solve` as itself, with every solver: mim_solvers' CSQP lets no
exception cross its C++ loop (std::terminate: the process aborted, a run's rollout lost).

The solves that could abort run in a child process, so that a regression fails the test
instead of killing the test session.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest
from conftest import REFERENCE_URDF

pytest.importorskip("crocoddyl")
from uvms_pin.ocp import problems

#: a problem whose running cost raises ``RAISED`` at its ``RAISE_AT``-th residual
SCRIPT = textwrap.dedent(
    """
    import os, signal, sys, warnings
    import numpy as np, pinocchio as pin
    import uvms_pin as up
    from uvms_pin.ocp import costs, problems

    solver, raised, raise_at = sys.argv[1], sys.argv[2], int(sys.argv[3])
    # Ctrl-C taken as an interactive run takes it, even when the test runner was started
    # with SIGINT ignored (a background job), which its children inherit
    signal.signal(signal.SIGINT, signal.default_int_handler)
    uvms = up.load_uvms({urdf!r})
    x0 = np.r_[pin.neutral(uvms.model), np.zeros(uvms.nv)]
    calls = []

    class Faulty(costs.CostTerm):
        def __init__(self):
            super().__init__(np.ones(1), 1, "faulty")

        def residual(self, model, data, x, u, contact=None):
            calls.append(1)
            if len(calls) == raise_at and raised == "ValueError":
                raise ValueError("my cost's bug")
            if len(calls) == raise_at:  # Ctrl-C, landing in a node
                os.kill(os.getpid(), signal.SIGINT)
            return np.zeros(1)

        def jacobians(self, model, data, x, u, contact=None):
            return np.zeros((1, 2 * model.nv)), np.zeros((1, u.size))

    bounds = (-np.ones(uvms.nv), np.ones(uvms.nv))
    problem = problems.shooting_problem(
        uvms, x0, lambda nu: [(Faulty(), 1.0), (costs.Effort(np.ones(nu)), 1.0)],
        lambda nu: [(Faulty(), 1.0)], nodes=10, dt_s=0.02,
        actuators=problems.Actuators(None, bounds, as_constraints=solver == "csqp"),
    )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            problems.solve(problem, iterations=3, solver=solver)
        except (Exception, KeyboardInterrupt) as exc:
            print("raised", type(exc).__name__, exc)
    for warned in caught:
        print("warned", warned.category.__name__, warned.message)
    # the problem solves again once the cost is mended (no error left behind)
    solved = problems.solve(problem, iterations=3, solver=solver)
    print("solved again", np.isfinite(solved.cost))
    """
).format(urdf=str(REFERENCE_URDF))


@pytest.mark.parametrize("solver", problems.SOLVERS)
@pytest.mark.parametrize("raised", ["ValueError", "KeyboardInterrupt"])
def test_an_error_in_a_node_reaches_the_caller_of_solve(tmp_path, solver, raised):
    """Raised at the 15th residual (inside the solver's first pass over the nodes)."""
    if solver == "csqp":
        pytest.importorskip("mim_solvers")
    script = tmp_path / "faulty.py"
    script.write_text(SCRIPT)
    done = subprocess.run(
        [sys.executable, str(script), solver, raised, "15"],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert done.returncode == 0, done.stderr  # not SIGABRT (-6)
    expected = (
        "raised ValueError my cost's bug" if raised == "ValueError" else "raised KeyboardInterrupt"
    )
    assert expected in done.stdout, done.stdout + done.stderr
    assert "solved again True" in done.stdout, done.stdout + done.stderr


def test_an_error_outside_solve_is_a_warning_and_nan(tmp_path):
    """crocoddyl's problem.calc called directly (not in a solve) cannot carry the error
    either: a NodeErrorWarning names it, the node's cost is not a number one could mistake
    for a solution's; the next solve starts afresh."""
    script = tmp_path / "faulty.py"
    script.write_text(
        SCRIPT.replace(
            "problems.solve(problem, iterations=3, solver=solver)",
            "print('cost', problem.calc([x0] * 11, [np.zeros(uvms.nv)] * 10))",
            1,
        )
    )
    done = subprocess.run(
        [sys.executable, str(script), "box_fddp", "ValueError", "1"],
        capture_output=True, text=True, timeout=300, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert "warned NodeErrorWarning an OCP node's calc raised ValueError: my cost's bug" in (
        done.stdout
    ), done.stdout + done.stderr
    assert float(lines[0].split()[1]) >= 1e20, lines  # (1e30 x dt)
    assert "solved again True" in done.stdout
