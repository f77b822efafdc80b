"""One arm's row of the comparison: its columns, the blank row, and ``row.json``."""

from __future__ import annotations

import math
from pathlib import Path

from uvms_pin.results.atomic import write_json_atomic

#: (key of the row, column title of the Markdown table), in table order.
COLUMNS: tuple[tuple[str, str], ...] = (
    ("arm", "arm"),
    ("n_joints", "joints"),
    ("status", "status"),
    ("arm_mass_kg", "arm mass [kg]"),
    ("system_mass_kg", "system mass [kg]"),
    ("net_buoyancy_before_N", "net buoyancy before trim [N]"),
    ("net_buoyancy_after_N", "net buoyancy after trim [N]"),
    ("foam_volume_L", "foam [L]"),
    ("ballast_kg", "ballast [kg]"),
    ("bg_cm", "BG [cm]"),
    ("initial_orientation_error_deg", "initial orientation vs reference [deg]"),
    ("force_error_rms_N", "force error RMS [N]"),
    ("force_error_rms_after_transient_N", "force error RMS after transient [N]"),
    ("funnel_margin_min_first", "min funnel margin 1st"),
    ("funnel_margin_min_second", "min funnel margin 2nd"),
    ("task_position_error_rms_m", "tracking position error RMS [m]"),
    ("task_orientation_error_rms_rad", "tracking orientation error RMS [rad]"),
    ("vehicle_force_peak_N", "peak vehicle force [N]"),
    ("vehicle_torque_peak_Nm", "peak vehicle torque [N m]"),
    ("joint_torque_peak_Nm", "peak joint torque [N m]"),
    ("simulated_time_s", "simulated [s]"),
    ("derived_hydro_bodies", "derived hydro bodies"),
    ("dry_links", "dry links"),
    ("reason", "why"),
)


#: The columns of one kind of task: a contact task's force and funnels, a tracking task's
#: errors (`uvms_pin.results.task_metrics`). The Markdown table and the figure show those
#: some arm has a value of; the CSV has every column.
TASK_COLUMNS = {
    "force": (
        "force_error_rms_N",
        "force_error_rms_after_transient_N",
        "funnel_margin_min_first",
        "funnel_margin_min_second",
    ),
    "tracking": ("task_position_error_rms_m", "task_orientation_error_rms_rad"),
}


def has_values(rows: list[dict], key: str) -> bool:
    """Whether some row has a number in column ``key`` (NaN: never got)."""
    return any(math.isfinite(float(row.get(key, math.nan))) for row in rows)


def nan_row(name: str) -> dict:
    """The row of arm ``name`` before anything is known: NaN numbers, empty texts."""
    row = {key: math.nan for key, _ in COLUMNS}
    row.update(arm=name, status="", reason="", dry_links="", derived_hydro_bodies=0)
    return row


def write_row(row: dict, keep_dir: Path | None) -> None:
    """``keep_dir/row.json`` (nothing if ``keep_dir`` is None)."""
    if keep_dir is not None:
        keep_dir.mkdir(parents=True, exist_ok=True)
        write_json_atomic(keep_dir / "row.json", row)  # NaN (a metric never got): null
