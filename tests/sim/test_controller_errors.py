"""A controller that raises stops the run with status ``error``: the rollout up to the last
logged sample is kept, the message names the method, the time and the exception, and the
frames of the user's own code travel with it (the command line shows them as such)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT

from uvms_pin.control.base import Controller
from uvms_pin.errors import ControllerError, FunnelViolation
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

REALISTIC = ROOT / "scenarios" / "realistic_force_tracking.toml"  # sampled, 500 Hz
PASSIVE = ROOT / "scenarios" / "passive_current.toml"  # continuous, fixed-step RK4


class RaisesLater(Controller):
    def __init__(self, nv: int, at_s: float, where: str = "compute"):
        self.nv, self.at_s, self.where, self.t = nv, at_s, where, 0.0

    def compute(self, time_s, measurement):
        self.t = time_s
        if self.where == "compute" and time_s > self.at_s:
            return _users_helper(time_s)
        return np.zeros(self.nv)

    def signals(self):
        if self.where == "signals" and self.t > self.at_s:
            raise KeyError("e_x")
        return {}

    def reset(self):
        if self.where == "reset":
            raise RuntimeError("no hardware")


def _users_helper(time_s):
    return np.zeros(3) * [][0]  # IndexError, deep in the user's code


def _run(path, controller, duration_s=0.3):
    scenario = load_scenario(path, {"scenario.duration_s": duration_s})
    scenario.controller_factory = lambda uvms: controller
    return simulate(scenario, progress=False)


@pytest.mark.parametrize("path", [REALISTIC, PASSIVE], ids=["sampled", "continuous"])
def test_a_controller_raising_mid_run_keeps_the_rollout_and_its_traceback(path):
    with pytest.raises(ControllerError) as info:
        _run(path, RaisesLater(10, at_s=0.1))
    exc = info.value
    assert str(exc).startswith("the controller's compute() raised at t = 0.1")
    assert "IndexError: list index out of range" in str(exc)
    assert isinstance(exc.__cause__, IndexError)
    rollout = exc.rollout
    assert rollout.status.kind == "error" and not rollout.status.ok
    assert rollout.status.time_s == pytest.approx(exc.time_s) and 0.1 < exc.time_s < 0.13
    assert len(rollout) >= 5 and 0.08 <= rollout.time_s[-1] <= exc.time_s
    assert np.all(np.isfinite(rollout.q))
    # the traceback: the user's frames only, ending with the exception
    trace = rollout.metadata["error_traceback"]
    assert trace == exc.user_traceback
    assert trace.startswith("Traceback (most recent call last):")
    assert "in _users_helper" in trace and __file__ in trace
    assert "uvms_pin" not in trace and trace.rstrip().endswith("list index out of range")


@pytest.mark.parametrize("where", ["signals", "reset"])
def test_every_method_of_the_controller_is_guarded(where):
    with pytest.raises(ControllerError, match=rf"the controller's {where}\(\) raised") as info:
        _run(REALISTIC, RaisesLater(10, at_s=0.05, where=where))
    assert info.value.rollout.status.kind == "error"
    assert info.value.user_traceback  # a user's controller: its frames


def test_a_funnel_violation_is_still_a_funnel_violation():
    """The PPC's verdict is not an error of the controller's code."""
    scenario = load_scenario(
        REALISTIC,
        {"scenario.duration_s": 0.5, "controller.rho_inf_x": [0.01] * 3 + [0.2] * 3,
         "controller.l_x_per_s": [3.0, 3.0, 3.0, 1.0, 1.0, 1.0]},
    )  # fmt: skip
    with pytest.raises(FunnelViolation) as info:
        simulate(scenario, progress=False)
    assert info.value.rollout.status.kind == "FunnelViolation"


def test_a_user_constructor_raising_names_its_parameters_with_the_traceback(tmp_path):
    (tmp_path / "my_ctrl_raise.py").write_text(
        "from uvms_pin.control.base import Controller\n"
        "class C(Controller):\n"
        "    def __init__(self, uvms, gain=1.0):\n"
        "        self.gain = {}['missing']\n"
        "    def compute(self, t, m):\n"
        "        return None\n"
    )
    text = PASSIVE.read_text().replace('"uvms_lbv150"', f'"{ROOT / "models" / "uvms_lbv150.urdf"}"')
    text += '\n[controller]\ntype = "my_ctrl_raise:C"\ngain = 2.0\n'
    (tmp_path / "s.toml").write_text(text)
    from uvms_pin.errors import ScenarioError

    with pytest.raises(ScenarioError, match=r"rejected its parameters \(gain\): KeyError") as info:
        load_scenario(tmp_path / "s.toml")
    assert "my_ctrl_raise.py" in info.value.user_traceback
    assert "self.gain = {}['missing']" in info.value.user_traceback


def test_a_user_constructor_refusing_a_parameter_is_its_message_without_a_traceback(tmp_path):
    """A ParameterError from the constructor is a refusal made on purpose (e.g.
    `uvms_pin.checks.finite_parameters`): its message is the error, no frames shown."""
    (tmp_path / "my_ctrl_refuse.py").write_text(
        "from uvms_pin.checks import finite_parameters\n"
        "from uvms_pin.control.base import Controller\n"
        "class C(Controller):\n"
        "    def __init__(self, uvms, gain=1.0):\n"
        "        finite_parameters('mine', locals())\n"
        "    def compute(self, t, m):\n"
        "        return None\n"
    )
    text = PASSIVE.read_text().replace('"uvms_lbv150"', f'"{ROOT / "models" / "uvms_lbv150.urdf"}"')
    (tmp_path / "s.toml").write_text(
        text + '\n[controller]\ntype = "my_ctrl_refuse:C"\ngain = nan\n'
    )
    from uvms_pin.errors import ScenarioError

    with pytest.raises(
        ScenarioError, match=r"rejected its parameters: mine: gain must be finite, got nan"
    ) as info:
        load_scenario(tmp_path / "s.toml")
    assert not getattr(info.value, "user_traceback", None)
