"""The robustness table (docs/paper.md): the realistic scenario, same gains, varied conditions.

    .venv/bin/python scripts/robustness_table.py [--duration 10] [--jobs 2] [--out out/robustness]

Each row is one full run of ``scenarios/realistic_force_tracking.toml`` with one change;
the table (Markdown) is printed and written to OUT/robustness.md with OUT/robustness.json.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np

from uvms_pin.errors import FunnelViolation, SimulationError
from uvms_pin.model.scaled import scaled_uvms
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.batch import run_batch

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = ROOT / "scenarios" / "realistic_force_tracking.toml"

# (label, scenario overrides, plant scale factor)
CASES = [
    ("nominal (K_f = 2 N/m)", {}, 1.0),
    ("K_f = 20 N/m", {"environment.stiffness_N_m": [20.0] * 3}, 1.0),
    ("K_f = 200 N/m", {"environment.stiffness_N_m": [200.0] * 3}, 1.0),
    ("K_f = 2000 N/m", {"environment.stiffness_N_m": [2000.0] * 3}, 1.0),
    ("disturbance x5", {"disturbance.amplitude": [0.75, 0.75, 0.75, 0.0, 0.0, 0.0]}, 1.0),
    ("noise x5 (+-0.1 N)", {"sensors.force_noise_N": 0.1}, 1.0),
    ("current 0.2 m/s along x", {"water.current_world_m_s": [0.2, 0.0, 0.0]}, 1.0),
    ("plant parameters x0.7", {}, 0.7),
    ("plant parameters x1.3", {}, 1.3),
]

# the paper's literal gains and funnels (plain J^+), on the thrust-limited vehicle
PAPER_CONTROLLER = {
    "controller.k_x": [0.2] * 6,
    "controller.k_zeta": [5.0] * 10,
    "controller.rho0_x": [1.0, 1.0, 1.0, 0.9, 0.9, 0.9],
    "controller.rho_inf_x": [0.2] * 6,
    "controller.l_x_per_s": [3.0] * 6,
    "controller.rho0_zeta": [1.0] * 10,
    "controller.rho_inf_zeta": [0.2] * 6 + [0.4] * 4,
    "controller.l_zeta_per_s": [2.2] * 10,
    "controller.velocity_weights": [1.0] * 10,
}
PAPER_CASES = [
    ("paper gains, thrust-limited, 500 Hz", PAPER_CONTROLLER, 1.0),
    (
        "paper gains, thrust-limited, 10 kHz",
        {**PAPER_CONTROLLER, "control.period_s": 1e-4, "integrator.step_s": 1e-4},
        1.0,
    ),
]


def case_scenario(overrides: dict, factor: float, duration: float):
    """The realistic scenario with one case's overrides and plant factor."""
    scenario = load_scenario(SCENARIO, {**overrides, "scenario.duration_s": duration})
    if factor != 1.0:
        scenario.plant.uvms = scaled_uvms(
            scenario.uvms,
            mass_scale=factor,
            added_mass_scale=factor,
            damping_scale=factor,
            buoyancy_scale=factor,
        )
    return scenario


def case_row(label: str, scenario, run) -> dict:
    """The table's row of one case's run (`uvms_pin.sim.batch.BatchRun`)."""
    if run.error is not None and not isinstance(run.error, (FunnelViolation, SimulationError)):
        raise run.error  # a bug or a bad input, not a result
    rollout = run.rollout
    failure = "" if run.error is None else str(run.error)
    metrics = rollout.metrics()
    actuation = scenario.plant.actuation
    saturated = np.array([actuation.saturated(c) for c in rollout.signals["tau_commanded"]])
    return {
        "case": label,
        "holds": not failure,
        "failure": failure,
        "saturation_fraction": float(saturated.mean()),
        **{
            k: metrics.get(k, math.nan)
            for k in (
                "simulated_time_s",
                "funnel_margin_min_first",
                "funnel_margin_min_second",
                "force_error_rms_after_transient_N",
                "vehicle_force_peak_N",
                "commanded_vehicle_force_peak_N",
                "joint_torque_peak_Nm",
            )
        },
    }


def markdown(rows: list[dict]) -> str:
    """One row per case. For a run that stopped, the margins are those of the samples logged
    before the stop and the force RMS is not given (no full steady state)."""
    head = (
        "| case | funnels hold | min margin 1st / 2nd | force RMS after transient [N] | "
        "peak vehicle force applied / commanded [N] | peak joint torque [N m] | "
        "control steps saturated | first failure |\n|---|---|---|---|---|---|---|---|\n"
    )
    lines = []
    for r in rows:
        failure = r["failure"].replace("funnel violated at ", "").split(" (|xi|")[0]
        rms = f"{r['force_error_rms_after_transient_N']:.3f}" if r["holds"] else "-"
        lines.append(
            f"| {r['case']} | {'yes' if r['holds'] else 'no'} "
            f"| {r['funnel_margin_min_first']:.3f} / {r['funnel_margin_min_second']:.3f} "
            f"| {rms} "
            f"| {r['vehicle_force_peak_N']:.0f} / {r['commanded_vehicle_force_peak_N']:.0f} "
            f"| {r['joint_torque_peak_Nm']:.2f} | {100 * r['saturation_fraction']:.0f} % "
            f"| {failure} |"
        )
    return head + "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=10.0)
    parser.add_argument("--jobs", type=int, default=2, help="threads")
    parser.add_argument("--out", type=Path, default=ROOT / "out" / "robustness")
    parser.add_argument(
        "--paper-gains",
        action="store_true",
        help="add the paper's literal gains on the limited vehicle",
    )
    args = parser.parse_args()
    cases = CASES + (PAPER_CASES if args.paper_gains else [])
    scenarios = [case_scenario(ov, factor, args.duration) for _, ov, factor in cases]
    # side by side on threads (the compiled loops release the interpreter lock), each run
    # exactly as alone
    runs = run_batch(scenarios, args.jobs)
    rows = [
        case_row(label, s, r) for (label, _, _), s, r in zip(cases, scenarios, runs, strict=True)
    ]
    table = markdown(rows)
    print(table)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "robustness.md").write_text(table)
    (args.out / "robustness.json").write_text(json.dumps(rows, indent=2))


if __name__ == "__main__":
    main()
