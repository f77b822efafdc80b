"""Hydrodynamic identification on the pool trials: fitted parameters, held-out RMSE, a figure."""

from __future__ import annotations

import json
import math
import time

from _common import producer_cli, publish_figure, scratch, uvms_pin, write_result

FIGURE = "_alt_002-0"  # the held-out trial whose roll the catalogue damping leaves oscillating


def _parameter_rows(result: dict) -> list[str]:
    rows = ["| parameter | catalogue | identified | sensitivity |", "|---|---|---|---|"]
    for name, p in result["parameters"].items():
        rows.append(f"| `{name}` | {p['start']:.4g} | {p['identified']:.4g} | {p['sensitivity']} |")
    return rows


def _trial_rows(result: dict) -> list[str]:
    rows = [
        "| trial | set | roll: catalogue -> identified | pitch: catalogue -> identified "
        "| Kolano's simulator: roll / pitch |",
        "|---|---|---|---|---|",
    ]
    for name, t in result["trials"].items():
        used = "identification" if name in result["identification_trials"] else "held out"
        published = (
            "-"
            if t["published_roll_rmse_deg"] is None
            else f"{t['published_roll_rmse_deg']:.2f} / {t['published_pitch_rmse_deg']:.2f}"
        )
        rows.append(
            f"| {name} | {used} | {t['start_roll_rmse_deg']:.2f} -> "
            f"{t['identified_roll_rmse_deg']:.2f} | {t['start_pitch_rmse_deg']:.2f} -> "
            f"{t['identified_pitch_rmse_deg']:.2f} | {published} |"
        )
    return rows


if __name__ == "__main__":
    producer_cli(__doc__)
    out = scratch("identification")
    started = time.perf_counter()
    uvms_pin(
        "identify",
        "data/hinsdale2023",
        "--fit",
        "default",
        "--out",
        str(out),
        "--quiet",
    )
    elapsed_min = (time.perf_counter() - started) / 60.0
    result = json.loads((out / "identification.json").read_text())
    held, used = result["held_out"], result["identification"]
    state = "converged" if result["converged"] else "**not converged**"
    body = (
        "`uvms-pin identify data/hinsdale2023 --fit default --out out/results/identification` "
        f"(Levenberg-Marquardt: {result['iterations']} steps tried, "
        f"{result['accepted_steps']} accepted, stopped by the `{result['stop_reason']}` "
        f"criterion, {state}; largest cosine between the residual and a Jacobian column "
        f"{result['gradient_cosine']:.1e}; RMS of the fit residual "
        f"{result['fit_rms_deg'][0]:.3f} -> {result['fit_rms_deg'][-1]:.3f} deg; "
        f"{elapsed_min:.0f} min on this machine).\n\n"
        + "\n".join(_parameter_rows(result))
        + f"\n\nIdentified properties of the recording: arm delay (the encoders' lag on the IMU "
        f"clock) {result['arm_delay_s']:.3f} s, IMU mounting yaw on the hull "
        f"{math.degrees(result['imu_yaw_rad']):.2f} deg.\n\n"
        "Mean RMSE [deg], catalogue -> identified: held-out trials roll "
        f"{held['mean_start_roll_rmse_deg']:.3f} -> {held['mean_identified_roll_rmse_deg']:.3f}, "
        f"pitch {held['mean_start_pitch_rmse_deg']:.3f} -> "
        f"{held['mean_identified_pitch_rmse_deg']:.3f}; identification trials roll "
        f"{used['mean_start_roll_rmse_deg']:.3f} -> {used['mean_identified_roll_rmse_deg']:.3f}, "
        f"pitch {used['mean_start_pitch_rmse_deg']:.3f} -> "
        f"{used['mean_identified_pitch_rmse_deg']:.3f}.\n\n" + "\n".join(_trial_rows(result)) + "\n"
    )
    publish_figure(out / f"identified{FIGURE}.png", f"identified{FIGURE}.png")
    write_result(
        "identification",
        "Identification of the trial vehicle's hull on the pool trials",
        "python scripts/results/identification.py",
        body,
    )
