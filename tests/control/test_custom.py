"""Your own controller (issue 11.4): ``[controller] type = "module:Class"`` is imported from
the scenario's directory, built by the documented contract, and recorded as what ran."""

from __future__ import annotations

import dataclasses
import textwrap

import numpy as np
import pinocchio as pin
import pytest
from conftest import ROOT

import uvms_pin as up
from uvms_pin.apps.cli.main import main
from uvms_pin.control.base import ZeroController
from uvms_pin.control.spec import ControllerSpec
from uvms_pin.scenario.custom_controller import load_controller_class
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

EXAMPLE = ROOT / "scripts" / "station_keeping" / "station_keeping.toml"

MODULE = '''
import numpy as np
from uvms_pin.control.base import Controller


class ConstantWrench(Controller):
    """tau = [wrench_body, 0...]."""

    def __init__(self, uvms, wrench_body, scale=1.0):
        self.tau = np.zeros(uvms.nv)
        self.tau[:6] = scale * np.asarray(wrench_body, dtype=float)

    def compute(self, time_s, measurement):
        return self.tau


class FromParams(ConstantWrench):
    @classmethod
    def from_params(cls, uvms, params):
        return cls(uvms, params["push"], scale=2.0)


class NotAController:
    def __init__(self, uvms):
        pass
'''


def scenario(tmp_path, controller: str, module_name: str = "my_ctrl"):
    (tmp_path / f"{module_name}.py").write_text(MODULE)
    path = tmp_path / "s.toml"
    path.write_text(
        textwrap.dedent(
            """
            [scenario]
            model = "lbv150"
            duration_s = 0.1
            [integrator]
            step_s = 0.005
            [output]
            log_period_s = 0.05
            """
        )
        + textwrap.dedent(controller)
    )
    return path


def test_module_class_runs_and_is_recorded(tmp_path):
    path = scenario(
        tmp_path,
        """
        [controller]
        type = "my_ctrl_a:ConstantWrench"
        wrench_body = [3.0, 0.0, 0.0, 0.0, 0.0, 0.0]
        scale = 0.5
        """,
        "my_ctrl_a",
    )
    loaded = load_scenario(path)
    rollout = simulate(loaded)
    np.testing.assert_allclose(rollout.tau[:, 0], 1.5)  # what the class computed
    record = rollout.metadata["controller"]
    assert record == {
        "class": "my_ctrl_a:ConstantWrench",
        "type": "my_ctrl_a:ConstantWrench",
        "params": {"wrench_body": [3.0, 0.0, 0.0, 0.0, 0.0, 0.0], "scale": 0.5},
    }
    rollout.save(tmp_path / "out")
    assert up.Rollout.load(tmp_path / "out").metadata["controller"] == record


def test_from_params_is_the_constructor_when_the_class_has_it(tmp_path):
    path = scenario(
        tmp_path,
        """
        [controller]
        type = "my_ctrl_b:FromParams"
        push = [0.0, 1.0, 0.0, 0.0, 0.0, 0.0]
        """,
        "my_ctrl_b",
    )
    rollout = simulate(load_scenario(path))
    np.testing.assert_allclose(rollout.tau[:, 1], 2.0)
    assert rollout.metadata["controller"]["class"] == "my_ctrl_b:FromParams"


def test_a_replaced_factory_records_the_class_that_ran(tmp_path):
    path = scenario(tmp_path, '[controller]\ntype = "none"\n')
    loaded = load_scenario(path)
    assert isinstance(loaded.controller_factory, ControllerSpec)
    assert loaded.controller_factory.type == "none"

    class Mine(ZeroController):
        pass

    replaced = dataclasses.replace(loaded, controller_factory=lambda u: Mine(u.nv))
    record = simulate(replaced).metadata["controller"]
    assert record["class"].endswith(
        ":test_a_replaced_factory_records_the_class_that_ran.<locals>.Mine"
    )
    assert record["type"] == record["class"]  # what ran, not the TOML's "none"
    assert record["params"] == {}  # ZeroController has no public attribute to record


def test_ppc_records_its_resolved_parameters():
    loaded = load_scenario(ROOT / "scenarios" / "paper_force_tracking.toml")
    params = loaded.controller_factory.params
    assert params["ee_frame"] == "ee"
    assert len(params["k_zeta"]) == loaded.uvms.nv  # after broadcasting, what ran
    assert params["desired_force"]["period_s"] == 2.0


@pytest.mark.parametrize(
    ("controller", "needle"),
    [
        ('type = "no_such_module_xyz:Foo"', "module 'no_such_module_xyz' not found"),
        (
            'type = "my_ctrl_c:ConstantWrenc"',
            "has no 'ConstantWrenc'; did you mean 'ConstantWrench'?",
        ),
        ('type = "my_ctrl_c:NotAController"', "derived from uvms_pin.control.base.Controller"),
        ('type = "my_ctrl_c:ConstantWrench"\nwrong = 1', "rejected its parameters (wrong)"),
        ('type = "my_ctrl_c:"', "expected 'package.module:ClassName'"),
        (
            'type = "pcc"',
            "must be one of computed_torque, impedance, joint_hold, mpc, none, pi_force, ppc, "
            "resolved_acceleration, task_priority or 'package.module:ClassName', got 'pcc' "
            "(did you mean 'ppc'?)",
        ),
    ],
)
def test_bad_controllers_are_named(tmp_path, controller, needle):
    path = scenario(tmp_path, f"[controller]\n{controller}\n", "my_ctrl_c")
    with pytest.raises(up.ScenarioError) as info:
        load_scenario(path)
    assert needle in str(info.value)
    assert "s.toml" in str(info.value)


def test_the_import_leaves_sys_path_as_it_was(tmp_path):
    import sys

    before = list(sys.path)
    (tmp_path / "my_ctrl_d.py").write_text(MODULE)
    cls = load_controller_class("my_ctrl_d:ConstantWrench", tmp_path)
    assert cls.__name__ == "ConstantWrench"
    assert sys.path == before


def test_the_station_keeping_example_holds_station(tmp_path):
    """scripts/station_keeping: the LBV150 alone in a 0.2 m/s current. At rest the PD force
    balances h (drag + net buoyancy): p - p_d = -R h_lin / K_p, to the noise's average."""
    out = tmp_path / "out"
    status = main(
        ["run", str(EXAMPLE), "--out", str(out), "--quiet", "--set", "scenario.duration_s=4"]
    )
    assert status == 0
    rollout = up.Rollout.load(out)
    assert rollout.metadata["controller"]["class"] == "station_keeping_pd:StationKeepingPD"
    kp = rollout.metadata["controller"]["params"]["kp_position_N_m"]
    uvms = up.load_uvms(ROOT / "models" / "lbv150.urdf")
    settled = rollout.time_s > 3.0
    offset = rollout.q[settled, :3].mean(axis=0) - np.array([0.0, 0.0, -2.0])
    q_end = rollout.q[-1]
    h = up.bias_forces(uvms, q_end, np.zeros(6), np.array([0.2, 0.0, 0.0]))
    rotation = pin.Quaternion(q_end[3:7]).toRotationMatrix()
    np.testing.assert_allclose(offset, -rotation @ h[:3] / kp, atol=1e-3)
    assert np.linalg.norm(offset) < 0.02  # holds station within 2 cm against ~2.4 N
    rpy = pin.rpy.matrixToRpy(rotation)
    np.testing.assert_allclose(rpy, [0.0, 0.0, 0.3], atol=0.03)
    assert np.max(np.abs(rollout.v[settled])) < 0.05
