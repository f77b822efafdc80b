"""What a user's script prints when it ends: nothing of nanobind's leak report.

A script keeping an OCP in a global, with a cost term of its own: the script's module ->
the problem -> (crocoddyl's C++, which the garbage collector cannot see through) -> the
nodes -> the term -> its class's methods -> the script's module. The interpreter frees that
cycle only after the compiled core's module is gone, and nanobind, at that point, reported
the core's objects the nodes reach as "leaked instances" of uvms-pin's bindings, with a
hint at a reference-counting bug. uvms_pin.ocp turns that report off; a
script that never imports it keeps nanobind's report, and leaks nothing.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest
from conftest import REFERENCE_URDF

from uvms_pin.physics.compiled.extension import core_available

pytestmark = pytest.mark.skipif(not core_available(), reason="the compiled core is not built")

CORE_ONLY = textwrap.dedent(
    """
    import numpy as np, pinocchio as pin
    import uvms_pin as up
    uvms = up.load_uvms({urdf!r})
    q, v = pin.neutral(uvms.model), np.zeros(uvms.nv)
    a = up.forward_dynamics(uvms, q, v, np.zeros(uvms.nv))
    da = up.forward_dynamics_derivatives(uvms, q, v, np.zeros(uvms.nv))
    print("done", np.isfinite(a).all())
    """
)

WITH_AN_OCP = CORE_ONLY + textwrap.dedent(
    """
    from uvms_pin.ocp import costs, problems

    class Mine(costs.CostTerm):  # a user's own term: its methods reach this module
        def __init__(self):
            super().__init__(np.ones(1), 1, "mine")

        def residual(self, model, data, x, u, contact=None):
            return np.zeros(1)

        def jacobians(self, model, data, x, u, contact=None):
            return np.zeros((1, 2 * model.nv)), np.zeros((1, u.size))

    x0 = np.r_[q, v]
    problem = problems.shooting_problem(
        uvms, x0, lambda nu: [(Mine(), 1.0), (costs.Effort(np.ones(nu)), 1.0)],
        lambda nu: [], nodes=3, dt_s=0.02,
    )
    solver = problems.solve(problem, iterations=2)
    print("solved", np.isfinite(solver.cost))
    """
)


def _stderr_of(script_text: str, tmp_path) -> tuple[str, str]:
    script = tmp_path / "script.py"
    script.write_text(script_text.format(urdf=str(REFERENCE_URDF)))
    done = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, timeout=300, check=False
    )
    assert done.returncode == 0, done.stderr
    return done.stdout, done.stderr


def test_a_script_with_an_ocp_in_a_global_ends_without_a_leak_report(tmp_path):
    pytest.importorskip("crocoddyl")
    out, err = _stderr_of(WITH_AN_OCP, tmp_path)
    assert "solved True" in out
    assert "leaked" not in err, err


def test_the_core_alone_leaks_nothing_at_exit(tmp_path):
    """nanobind's report stays on without the OCP layer: the core's own objects in globals
    are freed at exit (a reference-counting bug in the bindings would show here)."""
    out, err = _stderr_of(CORE_ONLY, tmp_path)
    assert "done True" in out
    assert "leaked" not in err, err
