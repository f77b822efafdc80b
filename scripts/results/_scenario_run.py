"""One scenario run as a result: the CLI run, its metrics as a table, its force figure."""

from __future__ import annotations

import json

from _common import ROOT, publish_figure, scratch, uvms_pin, write_result

from uvms_pin.results.rollout import Rollout

# (metrics.json key, label, format)
ROWS = (
    ("status", "status", "{}"),
    ("simulated_time_s", "simulated time [s]", "{:.3f}"),
    ("funnel_margin_min_first", "min funnel margin min(1 - \\|xi\\|), first level", "{:.3g}"),
    ("funnel_margin_min_second", "min funnel margin, second level", "{:.3g}"),
    ("transient_end_s", "force funnel transient ends at [s]", "{:.3g}"),
    ("force_error_rms_after_transient_N", "RMS force error after the transient [N]", "{:.3f}"),
    ("force_error_max_after_transient_N", "max force error after the transient [N]", "{:.3f}"),
    ("force_overshoot_N", "force overshoot [N]", "{:.3f}"),
    ("vehicle_force_peak_N", "peak vehicle force applied [N]", "{:.4g}"),
    ("commanded_vehicle_force_peak_N", "peak vehicle force commanded [N]", "{:.4g}"),
    ("vehicle_torque_peak_Nm", "peak vehicle torque [N m]", "{:.3g}"),
    ("joint_torque_peak_Nm", "peak joint torque [N m]", "{:.3g}"),
    ("joint_limit_excess_max_rad", "largest joint-limit excess [rad]", "{:.3g}"),
    ("orientation_error_final_rad", "final orientation error [rad]", "{:.3g}"),
    ("wall_time_s", "wall time [s] (machine-dependent)", "{:.2g}"),
)


def produce(
    name: str, scenario: str, title: str, figure: str, replay: bool = False, extra: str = ""
) -> None:
    """Run ``scenario`` with the CLI and write its metrics table (with the vertical contact
    force after the transient; with ``replay``, also the size of its replay.html), then
    ``extra`` (more Markdown)."""
    out = scratch(name)
    result = uvms_pin("run", scenario, "--out", str(out), "--quiet", *(["--html"] * replay))
    metrics = json.loads((out / "metrics.json").read_text())
    lines = ["| metric | value |", "|---|---|"]
    lines += [
        f"| {label} | {fmt.format(metrics[key])} |" for key, label, fmt in ROWS if key in metrics
    ]
    lines += _vertical_contact_force_row(out, metrics.get("transient_end_s"))
    if replay:
        size_mb = (out / "replay.html").stat().st_size / 1e6
        lines.append(f"| replay.html (uvms-pin run --html) [MB] | {size_mb:.1f} |")
    if metrics.get("error"):
        lines.append(f"| stopped because | {metrics['error']} |")
    body = (
        f"`uvms-pin run {scenario}` (exit code {result.returncode}), seed "
        f"{metrics['seed']}:\n\n" + "\n".join(lines) + f"\n\n![force](../{figure})\n" + extra
    )
    publish_figure(out / "force.png", figure)
    write_result(name, title, f"python scripts/results/{name}.py", body)
    assert (ROOT / "docs" / figure).is_file()


def _vertical_contact_force_row(out, transient_end_s: float | None) -> list[str]:
    """The contact force along world z after the transient, min / mean / max [N] (the
    force no controller asks for: what waves and the vehicle's motion leave)."""
    if transient_end_s is None:
        return []
    rollout = Rollout.load(out)
    after = rollout.time_s > transient_end_s
    fz = rollout.wrench_contact_world[after, 2]
    if not fz.size:
        return []
    return [
        f"| vertical contact force f_z after the transient, min / mean / max [N] | "
        f"{fz.min():.3f} / {fz.mean():.3f} / {fz.max():.3f} |"
    ]
