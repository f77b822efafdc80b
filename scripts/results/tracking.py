"""Tracking tasks: the end-effector circle (0.2 m diameter in 20 s at 2 m depth) on the
LBV150 + arm and the BlueROV2 Heavy + Alpha 5, each controller in still water and in a
0.2 m/s current, against the issue's targets (LBV150: position RMS <= 1 cm still, <= 3 cm
in the current, orientation RMS <= 2 deg, joints inside their limits)."""

import csv
import math

from _common import producer_cli, publish_figure, scratch, uvms_pin, write_result

CONTROLLERS = "task_priority,task_priority_ppc,computed_torque_task"
SCENARIOS = {
    "LBV150 + arm": "scenarios/lbv150_ee_circle.toml",
    "BlueROV2 Heavy + Alpha 5": "scenarios/bluerov_alpha5_ee_circle.toml",
}
CONDITIONS = {"still water": "[0,0,0]", "current 0.2 m/s (x)": "[0.2,0,0]"}


def _cell(value: str, scale: float, digits: int) -> str:
    number = float(value) if value else math.nan
    return "-" if math.isnan(number) else f"{scale * number:.{digits}f}"


def _rows(vehicle: str, condition: str, path) -> list[str]:
    lines = []
    with open(path) as f:
        for row in csv.DictReader(f):
            verdict = "yes" if row["success"] == "True" else f"no: {row['reason']}"
            lines.append(
                f"| {vehicle} | {condition} | {row['controller']} "
                f"| {_cell(row['task_position_error_rms_m'], 100, 2)} "
                f"| {_cell(row['task_position_error_max_m'], 100, 2)} "
                f"| {_cell(row['task_orientation_error_rms_rad'], 180 / math.pi, 2)} "
                f"| {_cell(row['joint_limit_excess_max_rad'], 1, 3)} "
                f"| {_cell(row['saturated_fraction'], 1, 2)} | {verdict} |"
            )
    return lines


if __name__ == "__main__":
    producer_cli(__doc__)
    out = scratch("tracking")
    table = [
        "| UVMS | water | controller | position RMS [cm] | position max [cm] | "
        "orientation RMS [deg] | joint past limit [rad] | saturated fraction | task held |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    commands = []
    for k, (vehicle, scenario) in enumerate(SCENARIOS.items()):
        for j, (condition, current) in enumerate(CONDITIONS.items()):
            run_dir = out / f"{k}_{j}"
            args = ("compare-controllers", scenario, "--controllers", CONTROLLERS,
                    "--set", f"water.current_world_m_s={current}")  # fmt: skip
            uvms_pin(*args, "--out", str(run_dir), "--quiet")
            commands.append(f"`uvms-pin {' '.join(args)}`")
            table += _rows(vehicle, condition, run_dir / "controllers.csv")
    publish_figure(out / "0_1" / "controllers_tracking.png", "tracking_lbv150_current.png")
    uvms_pin("run", SCENARIOS["LBV150 + arm"], "--out", str(out / "circle"), "--quiet")
    publish_figure(out / "circle" / "tracking.png", "tracking_lbv150_circle.png")
    body = (
        "Errors after the task's transient (5 s) of a 30 s run (one and a half turns), true "
        "poses (the controllers see noisy measurements: 1 mm, 1 mrad, 0.5 mrad, 2 mm/s); "
        "100 Hz control with zero-order hold, thrust and joint-torque limits. Task held: "
        "the run ends with every joint inside its limits and the position error within "
        "1 cm.\n\n"
        + "\n".join(table)
        + "\n\nCommands:\n\n"
        + "\n".join(f"- {c}" for c in commands)
        + "\n\n![LBV150 circle, task priority, still water](../tracking_lbv150_circle.png)\n"
        + "\n![LBV150 circle in a 0.2 m/s current, per controller](../tracking_lbv150_current.png)\n"
    )
    write_result("tracking", "End-effector tracking: controller x task x conditions",
                 "python scripts/results/tracking.py", body)  # fmt: skip
