"""``uvms-pin compare-controllers`` on a short run, and its bad inputs (exit 2, nothing written;
run by the command's ``main`` in this process, `run_cli_in_process`)."""

from __future__ import annotations

import csv
import math

import pytest
from cli_support import ROOT, run_cli
from conftest import run_cli_in_process

REALISTIC = ROOT / "scenarios" / "realistic_force_tracking.toml"


def test_compare_controllers_short_run(tmp_path):
    out = tmp_path / "cmp"
    result = run_cli(
        [
            "compare-controllers", str(REALISTIC), "--controllers", "ppc,pi_force,computed_torque,mpc",
            "--set", "scenario.duration_s=0.1", "--out", str(out), "--quiet",
        ],
        tmp_path,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    rows = list(csv.DictReader((out / "controllers.csv").open()))
    # mpc: the realistic scenario's [baselines.mpc] (crocoddyl is in the dev extra)
    assert [r["controller"] for r in rows] == ["ppc", "pi_force", "computed_torque", "mpc"]
    for row in rows:
        assert math.isfinite(float(row["force_error_rms_N"]))
        assert row["success"] in ("True", "False")
    # funnel margins only where there are funnels
    assert float(rows[0]["funnel_margin_first"]) > 0.0
    assert math.isnan(float(rows[1]["funnel_margin_first"]))
    for name in ("controllers.md", "controllers_force.png", "controllers_metrics.png"):
        assert (out / name).is_file()
    # a second run into the same directory needs --overwrite
    again = run_cli(
        ["compare-controllers", str(REALISTIC), "--controllers", "pi_force",
         "--set", "scenario.duration_s=0.1", "--out", str(out), "--no-figures"],
        tmp_path,
    )  # fmt: skip
    assert again.returncode == 2 and "--overwrite" in again.stderr


@pytest.mark.parametrize(
    "args, message",
    [
        (["--controllers", "ppc,lqr"], "lqr"),
        (["--controllers", "ppc,ppc"], "twice"),
        (["--set", "baselines.pi_force.damping=-1"], "damping"),
        (["--after", "100"], "--after"),
        (["--controllers", "ppc,mpc", "--set", "baselines.mpc.horizon_s=0.01"], "horizon_s"),
        (["--controllers", "mpc", "--set", "baselines.mpc.task='dance'"], "task"),
    ],
)
def test_compare_controllers_bad_input(tmp_path, args, message):
    out = tmp_path / "never"
    command = ["compare-controllers", str(REALISTIC), "--out", str(out), *args]
    result = run_cli_in_process(command, tmp_path)
    assert result.returncode == 2, result.stderr
    assert message in result.stderr and "Traceback" not in result.stderr
    assert not out.exists()


def test_robustness_set_through_the_study_runner(tmp_path):
    out = tmp_path / "robust"
    result = run_cli(
        [
            "compare-controllers", str(REALISTIC), "--controllers", "pi_force",
            "--set", "scenario.duration_s=0.1", "--robustness", "--jobs", "0",
            "--no-figures", "--quiet", "--out", str(out),
        ],
        tmp_path,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    main = next(csv.DictReader((out / "controllers.csv").open()))
    rows = {r["case"]: r for r in csv.DictReader((out / "robustness.csv").open())}
    assert set(rows) == {
        "nominal", "stiffness_x10", "plant_x1.3", "plant_x0.7", "noise_x5", "disturbance_x5",
    }  # fmt: skip
    # the nominal case is the comparison's own run (same seed, same everything)
    assert float(rows["nominal"]["force_error_rms_N"]) == pytest.approx(
        float(main["force_error_rms_N"]), rel=1e-12
    )
    # a stiffer environment changes the force the same motion produces
    assert rows["stiffness_x10"]["force_error_rms_N"] != rows["nominal"]["force_error_rms_N"]
    assert (out / "robustness" / "results.parquet").is_file()


def test_robustness_cases_scale_what_the_scenario_sets():
    from uvms_pin.apps.compare.robustness import robustness_cases

    raw = {
        "environment": {"stiffness_N_m": [2.0, 2.0, 2.0]},
        "sensors": {"force_noise_N": 0.02, "distribution": "uniform"},
        "disturbance": {"amplitude": [0.15, 0.0, 0.0, 0.0, 0.0, 0.0]},
    }
    cases = robustness_cases(raw)
    assert cases["stiffness_x10"][0] == {"environment.stiffness_N_m": [20.0, 20.0, 20.0]}
    assert cases["noise_x5"][0] == {"sensors.force_noise_N": pytest.approx(0.1)}
    assert cases["disturbance_x5"][0]["disturbance.amplitude"][0] == pytest.approx(0.75)
    assert set(cases["plant_x0.7"][1].values()) == {0.7}


def test_the_force_figure_is_titled_and_its_window_line_labelled(tmp_path):
    """It had no title, and a vertical line nothing named (issue 22, 19)."""
    from uvms_pin.apps.compare.figures import write_comparison_figures
    from uvms_pin.apps.compare.metrics import Criteria
    from uvms_pin.apps.compare.runs import compare_controllers, controller_scenarios

    scenarios = controller_scenarios(REALISTIC, ["ppc"], {"scenario.duration_s": 0.1})
    rows, rollouts = compare_controllers(scenarios, Criteria(0.05, 0.25, 0.5))
    written = write_comparison_figures(rows, rollouts, tmp_path, 0.05)
    assert [p.name for p in written] == ["controllers_force.png", "controllers_metrics.png"]
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # written whole

    from uvms_pin.apps.compare.figures import force_figure

    fig = force_figure(rollouts, 0.05)
    assert fig._suptitle.get_text().startswith("realistic_force_tracking: contact force f_x")
    lower = fig.axes[1]
    assert [t.get_text() for t in lower.get_legend().get_texts()] == [
        "after-transient window from t = 0.05 s (errors measured there)"
    ]


def test_a_tracking_comparison_says_when_the_run_ends_before_its_transient(tmp_path):
    """A run shorter than the task's transient has no error to judge: no controller holds
    the task ('position error RMS nan mm: holds the task' before), and says why; --after
    (the force task's window) is refused for a [task]."""
    station = str(ROOT / "scenarios" / "mpc_station_keeping.toml")
    out = tmp_path / "cmp"
    result = run_cli(
        [
            "compare-controllers", station, "--controllers", "task_priority",
            "--set", "scenario.duration_s=0.3", "--out", str(out), "--no-figures",
        ],
        tmp_path,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert "holds the task" not in result.stdout
    assert "no samples after the task's transient (t = 2 s; the run ends at 0.3 s)" in (
        result.stdout
    )
    with open(out / "controllers.csv") as f:
        (row,) = list(csv.DictReader(f))
    assert row["success"] == "False"
    refused = run_cli(
        [
            "compare-controllers",
            station,
            "--controllers",
            "task_priority",
            "--after",
            "1",
            "--out",
            str(tmp_path / "never"),
        ],
        tmp_path,
    )
    assert refused.returncode == 2 and "--set task.transient_s=S" in refused.stderr
    assert not (tmp_path / "never").exists()


@pytest.mark.parametrize(
    ("scenario", "expected"),
    [
        ("realistic_force_tracking", ["ppc", "pi_force", "impedance", "computed_torque", "mpc"]),
        ("mpc_force_tracking", ["mpc", "pi_force", "impedance", "computed_torque"]),
        ("lbv150_ee_circle", ["task_priority", "task_priority_ppc", "computed_torque_task"]),
        ("mpc_station_keeping", ["mpc", "task_priority"]),
        ("passive_still_water", ["pi_force", "impedance", "computed_torque"]),  # no [controller]
    ],
)
def test_without_controllers_a_scenario_compares_what_it_can_be_judged_by(scenario, expected):
    """Its own controller, its named variants and, on a force task only, the three force
    baselines: a tracking task's default no longer asks for the PPC it does not have."""
    from uvms_pin.scenario.baselines import comparable_controllers
    from uvms_pin.scenario.toml import read_toml

    raw = read_toml(ROOT / "scenarios" / f"{scenario}.toml", ValueError)
    assert comparable_controllers(raw) == expected


def test_a_tracking_scenario_compares_by_default_and_says_when_nothing_can_be_judged(tmp_path):
    out = tmp_path / "cmp"
    circle = ROOT / "scenarios" / "lbv150_ee_circle.toml"
    command = ["compare-controllers", str(circle), "--out", str(out), "--no-figures",
               "--set", "scenario.duration_s=0.2"]  # fmt: skip
    result = run_cli_in_process(command, tmp_path)
    assert result.returncode == 0, result.stderr
    rows = list(csv.DictReader((out / "controllers.csv").open()))
    assert [r["controller"] for r in rows] == [
        "task_priority", "task_priority_ppc", "computed_torque_task"
    ]  # fmt: skip
    # the run ends before the task's transient: no error to quote, and why
    assert "nan" not in result.stdout
    assert result.stdout.count("no errors to judge: fails: no samples after") == 3


def test_a_scenario_with_neither_task_is_refused_saying_so_not_naming_a_controller(tmp_path):
    out = tmp_path / "never"
    passive = ROOT / "scenarios" / "passive_still_water.toml"
    result = run_cli_in_process(["compare-controllers", str(passive), "--out", str(out)], tmp_path)
    assert result.returncode == 2, result.stderr
    assert "compares a force task" in result.stderr and "this scenario has neither" in result.stderr
    assert not out.exists()


RAISER = '''
from uvms_pin.control.base import Controller


class Raiser(Controller):
    """Cannot start: raises at its first tick, as a baseline does at a singular start."""

    def __init__(self, uvms):
        pass

    def compute(self, time_s, measurement):
        raise ValueError("cannot start here")
'''


def test_a_controller_that_cannot_start_is_a_row_and_the_others_are_still_compared(tmp_path):
    """A controller stopped before its first sample (a force baseline's Euler angles at a
    tool pointing straight down) stopped the whole comparison; it is a row saying why now,
    without numbers and without a curve, and the others are compared and drawn."""
    (tmp_path / "raiser.py").write_text(RAISER)
    scenario = tmp_path / "s.toml"
    scenario.write_text(REALISTIC.read_text())
    out = tmp_path / "cmp"
    command = [
        "compare-controllers", str(scenario), "--controllers", "raiser:Raiser,pi_force",
        "--set", 'controller={type="raiser:Raiser"}', "--set", "scenario.duration_s=0.1",
        "--out", str(out),
    ]  # fmt: skip
    result = run_cli_in_process(command, tmp_path)
    assert result.returncode == 0, result.stderr
    rows = list(csv.DictReader((out / "controllers.csv").open()))
    assert [r["controller"] for r in rows] == ["raiser:Raiser", "pi_force"]
    assert rows[0]["status"] == "stopped" and rows[0]["success"] == "False"
    assert (
        "cannot start here" in rows[0]["reason"] and "before its first sample" in rows[0]["reason"]
    )
    assert math.isnan(float(rows[0]["force_error_rms_N"]))
    assert math.isfinite(float(rows[1]["force_error_rms_N"]))
    assert "raiser:Raiser" in result.stdout and "no errors to judge" in result.stdout
    assert "nan" not in result.stdout
    for name in ("controllers.md", "controllers_force.png", "controllers_metrics.png"):
        assert (out / name).is_file()


def test_a_metric_of_your_own_that_fails_stops_no_tracking_comparison(tmp_path):
    """A tracking row's columns are built-in metrics: your failing metric is not computed
    for them (it stopped the whole comparison)."""
    (tmp_path / "cmp_metrics_broken.py").write_text(
        "def boom(rollout):\n    raise ValueError('x')\n"
    )
    scenario = tmp_path / "circle.toml"
    circle = (ROOT / "scenarios" / "lbv150_ee_circle.toml").read_text()
    scenario.write_text(circle + '\n[metrics]\nextra = ["cmp_metrics_broken:boom"]\n')
    out = tmp_path / "cmp"
    command = ["compare-controllers", str(scenario), "--out", str(out), "--no-figures",
               "--controllers", "task_priority", "--set", "scenario.duration_s=0.2"]  # fmt: skip
    result = run_cli_in_process(command, tmp_path)
    assert result.returncode == 0, result.stderr
    rows = list(csv.DictReader((out / "controllers.csv").open()))
    assert [r["controller"] for r in rows] == ["task_priority"]
