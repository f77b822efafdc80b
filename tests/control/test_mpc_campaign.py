"""A user's campaign on the MPC controller in scenarios: bad [controller] values on the
command line, end-to-end short runs of station keeping and the force task (deterministic),
and ``compare-controllers`` with the mpc. In-process ``uvms-pin`` (`main`), short runs.

crocoddyl is in the dev extra; without it these tests skip.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from conftest import ROOT

from uvms_pin.apps.cli.main import main

pytest.importorskip("crocoddyl")

STATION = ROOT / "scenarios" / "mpc_station_keeping.toml"
FORCE = ROOT / "scenarios" / "mpc_force_tracking.toml"


def _cli(capsys, *args: str) -> tuple[int, str]:
    code = main(list(args))
    return code, capsys.readouterr().err


@pytest.mark.parametrize(
    ("setting", "key"),
    [
        ("controller.warm_start='yes'", "controller.warm_start"),
        ("controller.solver='BoxFDDP'", "box_fddp, fddp, csqp"),
        ("controller.integrator='RK4'", "euler, rk4"),
        ("controller.iterations=0", "controller.iterations"),
        ("controller.iterations=2.5", "controller.iterations"),
        ("controller.rate_hz=-5", "controller.rate_hz"),
        ("controller.dt_s=0", "controller.dt_s"),
        ("controller.dt_s=2.0", "horizon_s"),
        ("controller.horizn_s=1.0", "controller.horizon_s"),  # a typo: the hint
        ("controller.model_error={dampin_scale=1.1}", "controller.model_error.damping_scale"),
        ("controller.model_error={damping_scale=-1.0}", "controller.model_error.damping_scale"),
        ("controller.current_world_m_s=[0.1, 0.2]", "controller.current_world_m_s"),
        ("controller.pose_weights=[1.0, 1.0]", "controller.pose_weights"),
        # every DoF's limit 0: a plan without an input (was: accepted, the MPC did nothing)
        ("controller.tau_limits=[0,0,0,0,0,0,0,0,0,0]", "controller.tau_limits"),
    ],
)
def test_bad_mpc_values_exit_2_naming_the_key(tmp_path, capsys, setting, key):
    out = tmp_path / "out"
    short = "scenario.duration_s=0.05"  # (what is accepted by mistake ends soon)
    code, err = _cli(
        capsys, "run", str(STATION), "--out", str(out), "--set", setting, "--set", short
    )
    assert code == 2, err
    assert key in err and "Traceback" not in err, err
    assert not out.exists()


@pytest.mark.parametrize("scenario", [STATION, FORCE], ids=["station", "force"])
def test_mpc_runs_end_to_end_shortened_and_twice_bit_for_bit(
    tmp_path, capsys, monkeypatch, scenario
):
    """0.1 s of each MPC scenario through `uvms-pin run`, shortened by
    UVMS_PIN_MAX_DURATION_S, with a perturbed model, RK4 nodes and plain FDDP: exit 0, and
    the same seed twice gives the same rollout, bit for bit."""
    monkeypatch.setenv("UVMS_PIN_MAX_DURATION_S", "0.1")
    settings = [
        "--set", "controller.model_error={damping_scale=1.3, added_mass_scale=0.8}",
        "--set", "controller.integrator='rk4'",
        "--set", "controller.solver='fddp'",
    ]  # fmt: skip
    runs = []
    for k in range(2):
        out = tmp_path / f"run{k}"
        code, err = _cli(capsys, "run", str(scenario), "--out", str(out), *settings)
        assert code == 0, err
        runs.append(np.load(out / "rollout.npz"))
    first, again = runs
    assert first["time_s"][-1] == pytest.approx(0.1, abs=0.02)
    assert np.all(np.isfinite(first["q"]))
    for name in first.files:
        np.testing.assert_array_equal(again[name], first[name], err_msg=name)


def test_compare_controllers_runs_the_mpc_on_the_force_task_with_csqp(tmp_path, capsys):
    out = tmp_path / "cmp"
    code, err = _cli(
        capsys, "compare-controllers", str(FORCE), "--controllers", "mpc,pi_force",
        "--set", "scenario.duration_s=0.1", "--set", "controller.solver='csqp'",
        "--out", str(out), "--quiet", "--no-figures",
    )  # fmt: skip
    assert code == 0, err
    rows = (out / "controllers.csv").read_text().splitlines()
    assert [r.split(",")[0] for r in rows[1:]] == ["mpc", "pi_force"]


def test_compare_controllers_refuses_a_scenario_without_a_force_task(tmp_path, capsys):
    """The station-keeping MPC scenario without its [task] has no [environment] nor [task]:
    compare-controllers compares force tracking or a [task]; it was a KeyError traceback
    (exit 1) after every controller had run."""
    text = STATION.read_text()
    start, end = text.index("[task]"), text.index("[baselines.task_priority]")
    (tmp_path / "no_task.toml").write_text(text[:start] + text[end:])
    out = tmp_path / "cmp"
    code, err = _cli(
        capsys, "compare-controllers", str(tmp_path / "no_task.toml"), "--controllers", "mpc",
        "--set", "scenario.duration_s=0.1", "--out", str(out), "--quiet", "--no-figures",
    )  # fmt: skip
    assert code == 2, err
    assert "force" in err and "[task]" in err and "Traceback" not in err, err
    assert not out.exists()


def test_compare_controllers_on_station_keeping_in_a_sea(tmp_path, capsys):
    """The MPC beside task-priority control holding the vehicle's pose in an irregular sea
    (the scenario's [task] hold, 0.4 s): one row each, both holding the station within the
    task's 0.1 m, the MPC's position error no larger than 1 cm."""
    out = tmp_path / "cmp"
    code, err = _cli(
        capsys, "compare-controllers", str(STATION), "--controllers", "mpc,task_priority",
        "--set", "scenario.duration_s=0.4", "--set", "task.transient_s=0.0",
        "--set", "water.sea={significant_height_m=0.5, peak_period_s=5.0}",
        "--out", str(out), "--quiet", "--no-figures",
    )  # fmt: skip
    assert code == 0, err
    table = pd.read_csv(out / "controllers.csv").set_index("controller")
    assert list(table.index) == ["mpc", "task_priority"]
    assert table["success"].tolist() == [True, True], table
    assert table.loc["mpc", "task_position_error_max_m"] < 0.01, table
