"""Compliant or rigid moving contacts: every single-robot scenario whose robot touches a moving
body (a free object or a fixture's links), run both ways with `uvms-pin run`, side by side
(its own success metric, what it grasped or pushed, the constraint solves kept after stalling
and the run's speed)."""

from __future__ import annotations

import json

from _common import producer_cli, scratch, uvms_pin, write_result

#: scenario -> (its success metric's key and label, a second number's key and label)
SCENARIOS = {
    "push_object": (("object_box_displacement_m", "box pushed [m]"), None),
    "gripper_close": (
        ("object_rod_displacement_m", "rod displacement [m]"),
        ("world_contact_force_peak_N", "peak contact force [N]"),
    ),
    "object_recovery": (("placed", "placed (1 yes)"), ("grasp_slip_m", "slip in the grasp [m]")),
    "valve_turn": (("valve_turned_rad", "valve turned [rad]"), None),
    "valve_panel": (("task_settled", "task settled (1 yes)"), None),
    "hot_stab": (
        ("insertion_depth_m", "insertion depth [m]"),
        ("stab_slip_m", "slip in the grasp [m]"),
    ),
}
MODES = ("compliant", "rigid")


def _row(name: str, mode: str, run: dict, solves: dict) -> str:
    first, second = SCENARIOS[name]
    numbers = [f"{first[1]} {run.get(first[0], float('nan')):.4g}"]
    if second is not None:
        numbers.append(f"{second[1]} {run.get(second[0], float('nan')):.4g}")
    stalled = solves.get("stalled", 0)
    worst = solves.get("worst_stalled_residual_m_s", 0.0)
    kept = f"{stalled} (worst {worst:.2g} m/s)" if stalled else "0"
    return (
        f"| {name} | {mode} | {run.get('status', '?')} | {'; '.join(numbers)} | {kept} "
        f"| {run.get('real_time_factor', float('nan')):.2f} |"
    )


def main() -> None:
    producer_cli(__doc__)
    out = scratch("contact_modes")
    lines = [
        "| scenario | moving contacts | status | its numbers | solves kept after stalling "
        "| real-time factor |",
        "|---|---|---|---|---|---|",
    ]
    python = []  # runs not compiled: none expected
    for name in SCENARIOS:
        for mode in MODES:
            folder = out / f"{name}-{mode}"
            uvms_pin(
                "run", f"scenarios/{name}.toml", "--out", str(folder), "--quiet",
                "--set", f'world.moving_contact="{mode}"',
            )  # fmt: skip
            run = json.loads((folder / "metrics.json").read_text())
            record = json.loads((folder / "rollout.json").read_text())
            lines.append(_row(name, mode, run, record.get("constraint_solves", {})))
            if "one compiled call" not in record["world"]["world"].get("integration", ""):
                python.append(f"{name} {mode}")
    if python:
        raise SystemExit(f"not one compiled call a period: {python}")
    body = (
        "Each scenario as shipped (`moving_contact` unset is compliant) and with "
        "`--set 'world.moving_contact=\"rigid\"'`; the real-time factor is simulated time over "
        "wall time on this machine, one core (machine-dependent). Every run is one compiled call "
        "a control period (the runs' metadata, `world.integration`).\n\n" + "\n".join(lines) + "\n"
    )
    write_result(
        "contact_modes", "Compliant or rigid moving contacts, scenario by scenario",
        "python scripts/results/contact_modes.py", body,
    )  # fmt: skip


if __name__ == "__main__":
    main()
