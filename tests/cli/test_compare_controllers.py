"""``uvms-pin compare-controllers`` on a short run, and its bad inputs (exit 2, nothing written)."""

from __future__ import annotations

import csv
import math

import pytest
from cli_support import ROOT, run_cli

REALISTIC = ROOT / "scenarios" / "realistic_force_tracking.toml"


def test_compare_controllers_short_run(tmp_path):
    out = tmp_path / "cmp"
    result = run_cli(
        [
            "compare-controllers", str(REALISTIC), "--controllers", "ppc,pi_force,computed_torque",
            "--set", "scenario.duration_s=0.1", "--out", str(out), "--quiet",
        ],
        tmp_path,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    rows = list(csv.DictReader((out / "controllers.csv").open()))
    assert [r["controller"] for r in rows] == ["ppc", "pi_force", "computed_torque"]
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
    ],
)
def test_compare_controllers_bad_input(tmp_path, args, message):
    out = tmp_path / "never"
    result = run_cli(["compare-controllers", str(REALISTIC), "--out", str(out), *args], tmp_path)
    assert result.returncode == 2, result.stderr
    assert message in result.stderr and "Traceback" not in result.stderr
    assert not out.exists()
