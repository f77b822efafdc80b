"""Run the same task with several arms on the same vehicle and tabulate the outcome.

For a scenario (e.g. ``scenarios/realistic_force_tracking.toml``) whose model is a UVMS URDF:

1. The scenario's model is split into the vehicle and its arm (:func:`split_urdf`); the
   target of the task is the reference tool tip placement in the world at the scenario's
   start (the spring anchor: the spring attaches where the tip is at t = 0), with the
   paper's initial tool orientation.
2. Each arm is mounted at the reference arm's mount point under the bow, rotated by
   ``mount_rpy`` (default upside down, (pi, 0, 0): a table-top arm's base z axis points
   down, so the arm hangs under the vehicle as the reference arm does).
3. The initial arm configuration is solved (:mod:`uvms_pin.apps.arms.initial`) with the vehicle at
   its initial pose; if the contact point cannot be reached the arm is reported
   "unreachable" and not run.
4. The system is trimmed at that configuration (:mod:`uvms_pin.model.trim`) unless ``trim=None``.
5. The scenario is loaded again with overrides: the merged model (written to
   ``OUT/models/NAME.urdf``), the initial joints, zero initial velocity, and every
   controller array with one entry per generalized velocity adapted to the new joint count:
   the vehicle's six entries are kept; for the arm part, ``k_zeta`` is
   alpha M_jj(q0) per joint (the diagonal of the mass matrix at the initial configuration,
   alpha the median of the reference arm's k_zeta / M_jj: the same loop rate per joint, which
   is what the sampled controller's stability depends on), and the other arrays take the
   median of the reference arm's entries.
6. The run's status is "ok", the exception that stopped it (FunnelViolation,
   SimulationError) or "joint limits" if a joint left its limits during the run.
7. With ``keep_rollouts``, each arm's row (``row.json``: status, reason, trim) and, when it
   ran, its rollout, ``metrics.json`` and figures (the paper's funnel figures show which
   error left its funnel, and when) go to ``OUT/<arm>/``, as ``uvms-pin run`` writes them.

The reference row is the scenario itself, unchanged.
"""

from __future__ import annotations

import csv
import io
import math
import sys
import tempfile
import time
import traceback
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from uvms_pin.apps.arms.initial import solve_initial_configuration
from uvms_pin.errors import FunnelViolation, ScenarioError, SimulationError, UvmsPinError
from uvms_pin.model.mount.catalog import REFERENCE, ArmEntry, resolve_arm
from uvms_pin.model.mount.hull import hull_box
from uvms_pin.model.mount.mount import mount_arm_detailed
from uvms_pin.model.mount.split import split_urdf
from uvms_pin.model.mount.text import write_text_file as write_text_atomic
from uvms_pin.model.trim import TrimSpec
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.dynamics import mass_matrix
from uvms_pin.results.atomic import atomic_path, write_json_atomic
from uvms_pin.scenario.scenario import load_scenario, simulate

__all__ = ["COLUMNS", "CompareSettings", "compare_arms", "write_comparison"]

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
    ("initial_orientation_error_deg", "initial orientation vs paper [deg]"),
    ("force_error_rms_N", "force error RMS [N]"),
    ("force_error_rms_after_transient_N", "force error RMS after transient [N]"),
    ("funnel_margin_min_first", "min funnel margin 1st"),
    ("funnel_margin_min_second", "min funnel margin 2nd"),
    ("vehicle_force_peak_N", "peak vehicle force [N]"),
    ("vehicle_torque_peak_Nm", "peak vehicle torque [N m]"),
    ("joint_torque_peak_Nm", "peak joint torque [N m]"),
    ("simulated_time_s", "simulated [s]"),
    ("derived_hydro_bodies", "derived hydro bodies"),
    ("dry_links", "dry links"),
    ("reason", "why"),
)


@dataclass(frozen=True)
class CompareSettings:
    """Options of :func:`compare_arms` (picklable: they go to worker processes)."""

    duration_s: float | None = None
    trim: TrimSpec | None = TrimSpec()  # noqa: RUF009 - frozen, immutable default
    mount_rpy: tuple[float, float, float] = (math.pi, 0.0, 0.0)
    ik_starts: int = 24
    seed: int = 0
    keep_rollouts: bool = False


def _nan_row(name: str) -> dict:
    row = {key: math.nan for key, _ in COLUMNS}
    row.update(arm=name, status="", reason="", dry_links="", derived_hydro_bodies=0)
    return row


def _vehicle_mass(urdf: Path) -> float:
    model = pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer())
    return float(sum(i.mass for i in model.inertias))


def _median_arm(values: list, n_ref: int) -> float:
    return float(np.median(np.asarray(values[6 : 6 + n_ref], dtype=float)))


def controller_overrides(
    raw_controller: dict, reference: UVMS, q_ref: np.ndarray, uvms: UVMS, q0: np.ndarray
) -> dict:
    """``controller.KEY`` overrides re-sizing every per-velocity array for ``uvms``."""
    nv_ref, n_ref, n = reference.nv, reference.n_arm_joints, uvms.n_arm_joints
    m_ref = np.diag(mass_matrix(reference, q_ref))[6:]
    m_new = np.diag(mass_matrix(uvms, q0))[6:]
    out = {}
    for key, value in raw_controller.items():
        if not (isinstance(value, list) and len(value) == nv_ref):
            continue
        vehicle = [float(x) for x in value[:6]]
        if key == "k_zeta":
            alpha = float(np.median(np.asarray(value[6:], dtype=float) / m_ref))
            arm = (alpha * m_new).tolist()
        else:
            arm = [_median_arm(value, n_ref)] * n
        out[f"controller.{key}"] = vehicle + arm
    if "null_space_target" in raw_controller:
        # the reference design pulls the arm back to its working pose: each arm's own
        out["controller.null_space_target"] = [float(x) for x in q0[7:]]
    return out


def _joint_limit_violation(rollout, uvms: UVMS) -> str:
    if len(rollout) == 0:
        return ""
    q = rollout.q[:, 7:]
    lo, hi = uvms.model.lowerPositionLimit[7:], uvms.model.upperPositionLimit[7:]
    bad = (q < lo - 1e-6) | (q > hi + 1e-6)
    if not np.any(bad):
        return ""
    k, j = np.argwhere(bad)[0]
    return (
        f"joint '{uvms.arm_joint_names[j]}' left its limits [{lo[j]:.3g}, {hi[j]:.3g}] "
        f"at t = {rollout.time_s[k]:.3f} s (q = {q[k, j]:.3g})"
    )


class ArmProgress:
    """Progress of one arm's run as text lines, one per tenth of the simulated duration.

    Picklable (worker processes get one); ``emit`` receives each line.
    """

    def __init__(self, arm: str, emit: Callable[[str], None]):
        self.arm = arm
        self.emit = emit
        self.start = time.perf_counter()
        self.next_fraction = 0.1

    def __call__(self, t_s: float, duration_s: float) -> None:
        fraction = t_s / duration_s if duration_s > 0 else 1.0
        if fraction + 1e-9 < self.next_fraction:
            return
        while self.next_fraction <= fraction + 1e-9:
            self.next_fraction += 0.1
        elapsed = time.perf_counter() - self.start
        self.emit(f"  {self.arm}: t = {t_s:.3g}/{duration_s:g} s ({elapsed:.0f} s)")


def print_to_stderr(line: str) -> None:
    """Default line sink of worker processes (a module function: picklable)."""
    print(line, file=sys.stderr, flush=True)


def _run(scenario, row: dict, keep_dir: Path | None = None, progress=None) -> None:
    """Simulate, fill the metrics and the status into ``row``; keep the outputs if asked."""
    try:
        rollout = simulate(scenario, progress=progress)
        status, reason = "ok", ""
    except FunnelViolation as exc:
        rollout, status, reason = exc.rollout, "FunnelViolation", str(exc)
    except SimulationError as exc:
        rollout, status, reason = exc.rollout, "SimulationError", str(exc)
    limits = _joint_limit_violation(rollout, scenario.uvms)
    if limits:
        reason = f"{limits}; {reason}" if reason else limits
        if status == "ok":
            status = "joint limits"
    metrics = rollout.metrics()
    for key in (
        "force_error_rms_N",
        "force_error_rms_after_transient_N",
        "funnel_margin_min_first",
        "funnel_margin_min_second",
        "vehicle_force_peak_N",
        "vehicle_torque_peak_Nm",
        "joint_torque_peak_Nm",
        "simulated_time_s",
    ):
        row[key] = float(metrics.get(key, math.nan))
    row["status"], row["reason"] = status, reason
    if keep_dir is not None:
        from uvms_pin.apps.outputs import write_outputs

        write_outputs(rollout, keep_dir)


def _keep_dir(out_dir: str, arm: str, settings: CompareSettings) -> Path | None:
    return Path(out_dir) / arm if settings.keep_rollouts else None


def _write_row(row: dict, keep_dir: Path | None) -> None:
    if keep_dir is not None:
        keep_dir.mkdir(parents=True, exist_ok=True)
        # NaN (a metric the arm never got) as JSON null
        clean = {k: None if isinstance(v, float) and math.isnan(v) else v for k, v in row.items()}
        write_json_atomic(keep_dir / "row.json", clean)


def _ee_rpy_error_deg(uvms: UVMS, q: np.ndarray, target: pin.SE3) -> float:
    data = uvms.model.createData()
    pin.framesForwardKinematics(uvms.model, data, q)
    rot = data.oMf[uvms.ee_frame_id].rotation
    return math.degrees(float(np.linalg.norm(pin.log3(rot.T @ target.rotation))))


@dataclass(frozen=True)
class _ArmJob:
    """What one arm's run needs besides its row (``entry`` None: the reference arm)."""

    entry: ArmEntry | None
    scenario_path: str
    out_dir: str
    vehicle_urdf: str
    mount_xyz: tuple[float, float, float]
    hull: tuple[np.ndarray, np.ndarray] | None
    settings: CompareSettings
    keep_dir: Path | None
    progress: ArmProgress | bool


def run_one_arm(
    name: str | ArmEntry,
    scenario_path: str,
    out_dir: str,
    vehicle_urdf: str,
    mount_xyz: tuple[float, float, float],
    hull: tuple[np.ndarray, np.ndarray] | None,
    settings: CompareSettings,
    emit: Callable[[str], None] | None = None,
) -> dict:
    """One row of the comparison (never raises for a per-arm failure).

    ``emit`` receives progress lines while the arm's run goes (none if None).
    """
    entry = None if name == REFERENCE else resolve_arm(name)
    row = _nan_row(name if entry is None else entry.name)
    keep_dir = _keep_dir(out_dir, row["arm"], settings)
    progress = ArmProgress(row["arm"], emit) if emit is not None else False
    job = _ArmJob(
        entry, scenario_path, out_dir, vehicle_urdf, mount_xyz, hull, settings, keep_dir, progress
    )
    try:
        _fill_row(row, job)
    except (UvmsPinError, ScenarioError) as exc:
        row.update(status="model error", reason=f"{type(exc).__name__}: {exc}")
    except Exception as exc:  # a per-arm bug must not lose the other rows
        row.update(
            status="error",
            reason=f"{type(exc).__name__}: {exc} | {traceback.format_exc(limit=2)!r}",
        )
    _write_row(row, keep_dir)
    return row


def _fill_row(row: dict, job: _ArmJob) -> None:
    """Mount, solve, trim and run one arm, filling ``row`` (raises on a model error)."""
    entry, settings = job.entry, job.settings
    overrides = {} if settings.duration_s is None else {"scenario.duration_s": settings.duration_s}
    vehicle_mass = _vehicle_mass(Path(job.vehicle_urdf))
    base = load_scenario(job.scenario_path, overrides)
    reference = base.uvms
    data = reference.model.createData()
    pin.framesForwardKinematics(reference.model, data, base.q0)
    target = data.oMf[reference.ee_frame_id].copy()
    if entry is None:
        row.update(
            n_joints=reference.n_arm_joints,
            arm_mass_kg=reference.mass_kg - vehicle_mass,
            system_mass_kg=reference.mass_kg,
            net_buoyancy_before_N=reference.net_buoyancy_N,
            net_buoyancy_after_N=reference.net_buoyancy_N,
            foam_volume_L=0.0,
            ballast_kg=0.0,
            initial_orientation_error_deg=0.0,
            derived_hydro_bodies=sum(b.params.derived for b in reference.hydro_bodies),
        )
        _run(base, row, job.keep_dir, job.progress)
        row["reason"] = ("the scenario as it is; " + row["reason"]).rstrip("; ")
        return
    mount_kw = dict(
        ee_link=entry.ee_link,
        arm_base_link=entry.arm_base_link,
        water_density_kg_m3=reference.water_density_kg_m3,
        allow_dry_links=True,
    )
    pose = (np.asarray(job.mount_xyz), np.asarray(settings.mount_rpy))
    mounted = mount_arm_detailed(job.vehicle_urdf, entry.urdf, pose, **mount_kw)
    uvms = mounted.uvms
    row.update(
        n_joints=uvms.n_arm_joints,
        arm_mass_kg=uvms.mass_kg - vehicle_mass,
        system_mass_kg=uvms.mass_kg,
        net_buoyancy_before_N=uvms.net_buoyancy_N,
        net_buoyancy_after_N=uvms.net_buoyancy_N,
        foam_volume_L=0.0,
        ballast_kg=0.0,
        derived_hydro_bodies=len(mounted.derived_bodies),
        dry_links=" ".join(mounted.dry_links),
    )
    ik = solve_initial_configuration(
        uvms, base.q0[:7], target, hull=job.hull, starts=settings.ik_starts, seed=settings.seed
    )
    row["initial_orientation_error_deg"] = math.degrees(ik.orientation_error_rad)
    if not ik.reachable:
        row.update(status="unreachable", reason=ik.reason)
        return
    q_arm = ik.q[7:]
    model_path = Path(job.out_dir) / "models" / f"{entry.name}.urdf"
    if settings.trim is not None:
        mounted = mount_arm_detailed(
            job.vehicle_urdf,
            entry.urdf,
            pose,
            trim=settings.trim,
            trim_joint_positions=q_arm,
            save_urdf=model_path,
            **mount_kw,
        )
        report = mounted.trim
        row.update(
            net_buoyancy_after_N=mounted.uvms.net_buoyancy_N,
            system_mass_kg=mounted.uvms.mass_kg,
            foam_volume_L=report.foam_volume_m3 * 1e3,
            ballast_kg=report.ballast_mass_kg,
            bg_cm=report.bg_after_m * 100.0,
        )
        trim_notes = "; ".join(report.notes)
    else:
        trim_notes = ""
        write_text_atomic(model_path, mounted.urdf_text)
    uvms = mounted.uvms
    scenario_overrides = dict(overrides)
    scenario_overrides.update(
        {
            "scenario.model": str(model_path.resolve()),
            "initial.joint_positions_rad": q_arm.tolist(),
            "initial.velocity": [0.0] * uvms.nv,
        }
    )
    scenario_overrides.update(
        controller_overrides(base.raw.get("controller", {}), reference, base.q0, uvms, ik.q)
    )
    scenario = load_scenario(job.scenario_path, scenario_overrides)
    _run(scenario, row, job.keep_dir, job.progress)
    if ik.orientation_error_rad > 1e-3:
        note = (
            f"initial tool orientation {math.degrees(ik.orientation_error_rad):.1f} deg "
            "from the paper's (the arm cannot match it at the contact point)"
        )
        row["reason"] = f"{note}; {row['reason']}" if row["reason"] else note
    if trim_notes:
        row["reason"] = f"{row['reason']}; trim: {trim_notes}".lstrip("; ")


def compare_arms(
    scenario_path: str | Path,
    arms: Sequence[str | ArmEntry],
    out_dir: str | Path,
    settings: CompareSettings = CompareSettings(),
    *,
    jobs: int = 1,
    progress: Callable[[str], None] | None = None,
) -> list[dict]:
    """Run the scenario's task with each arm; write the table and figure into ``out_dir``.

    ``arms``: "reference" (the scenario as it is), catalogue names, URDF paths or
    :class:`~uvms_pin.model.mount.catalog.ArmEntry` objects (a user arm with its ``ee_link``).
    Returns the rows (dicts keyed by :data:`COLUMNS`), in the order of ``arms``.
    ``progress`` receives a line when an arm starts, every tenth of its run and when it is
    done (from worker processes, with ``jobs > 1``, the lines during a run go to stderr).
    """
    scenario_path = Path(scenario_path)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    base = load_scenario(scenario_path)
    model_path = Path(base.uvms.source)
    for name in arms:  # fail early on names that are neither known nor files
        if name != REFERENCE:
            resolve_arm(name)
    with tempfile.TemporaryDirectory(prefix="uvms_pin_arms_") as tmp:
        split = split_urdf(model_path, tmp)
        hull = hull_box(split.vehicle_urdf, split.vehicle_link)
        args = [
            (
                name,
                str(scenario_path),
                str(out),
                str(split.vehicle_urdf),
                tuple(split.mount_pose.translation),
                hull,
                settings,
            )
            for name in arms
        ]
        rows: list[dict] = []
        start = time.perf_counter()
        if jobs > 1 and len(arms) > 1:
            emit = print_to_stderr if progress else None
            with ProcessPoolExecutor(max_workers=jobs) as pool:
                futures = [pool.submit(run_one_arm, *a, emit) for a in args]
                for future in futures:
                    rows.append(future.result())
                    if progress:
                        progress(_progress_line(rows[-1], start))
        else:
            for a in args:
                if progress:
                    label = a[0].name if isinstance(a[0], ArmEntry) else a[0]
                    progress(f"{label}: running ({time.perf_counter() - start:.0f} s elapsed)")
                rows.append(run_one_arm(*a, progress))
                if progress:
                    progress(_progress_line(rows[-1], start))
    write_comparison(rows, out, scenario=str(scenario_path), settings=settings)
    return rows


def _progress_line(row: dict, start: float) -> str:
    return f"{row['arm']}: {row['status']} ({time.perf_counter() - start:.0f} s elapsed)"


def _fmt(value) -> str:
    if isinstance(value, float):
        if math.isnan(value):
            return ""
        return f"{value:.4g}"
    return str(value)


def write_comparison(
    rows: list[dict], out_dir: Path, *, scenario: str = "", settings: CompareSettings | None = None
) -> list[Path]:
    """``comparison.csv``, ``comparison.md`` and ``comparison.png`` (atomically)."""
    out = Path(out_dir)
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow([key for key, _ in COLUMNS])
    for row in rows:
        writer.writerow([_fmt(row.get(key, "")) for key, _ in COLUMNS])
    write_text_atomic(out / "comparison.csv", buffer.getvalue())

    table_cols = [c for c in COLUMNS if c[0] not in ("reason", "dry_links")]
    lines = [
        f"# Arm comparison: {scenario}",
        "",
        "Same vehicle, same task, same vehicle controller; the arm part of the controller is "
        "adapted to each arm's joint count (see `uvms_pin.apps.arms.compare`).",
    ]
    if settings is not None:
        trim = (
            "none"
            if settings.trim is None
            else (
                f"foam {settings.trim.foam_density_kg_m3:g} kg/m^3 on top, lead ballast below, "
                f"target BG {settings.trim.bg_m * 100:g} cm"
            )
        )
        lines.append(
            f"Duration: {f'{settings.duration_s:g} s' if settings.duration_s else 'as in the scenario'}; mount rpy "
            f"{tuple(round(x, 4) for x in settings.mount_rpy)} rad; trim: {trim}."
        )
    lines += [
        "",
        "| " + " | ".join(label for _, label in table_cols) + " |",
        "|" + "---|" * len(table_cols),
    ]
    for row in rows:
        lines.append("| " + " | ".join(_fmt(row.get(k, "")) for k, _ in table_cols) + " |")
    lines += ["", "## Notes per arm", ""]
    for row in rows:
        note = row.get("reason") or "completed"
        dry = row.get("dry_links")
        if dry:
            note += f" (links with mass but no geometry, no buoyancy: {dry})"
        lines.append(f"- **{row['arm']}** ({row['status']}): {note}")
    write_text_atomic(out / "comparison.md", "\n".join(lines) + "\n")
    return [out / "comparison.csv", out / "comparison.md", _figure(rows, out)]


def _figure(rows: list[dict], out: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = [r["arm"] for r in rows]
    colors = [
        "tab:green"
        if r["status"] == "ok"
        else "tab:gray"
        if r["status"] == "unreachable"
        else "tab:red"
        for r in rows
    ]
    x = np.arange(len(rows))

    def values(key):
        return np.array([float(r.get(key, math.nan)) for r in rows])

    fig, axes = plt.subplots(2, 3, figsize=(14, 7.5))
    panels = [
        ("force_error_rms_N", "force error RMS [N]"),
        ("funnel_margin_min_first", "min funnel margin (1st / 2nd level)"),
        ("vehicle_force_peak_N", "peak vehicle force [N]"),
        ("joint_torque_peak_Nm", "peak joint torque [N m]"),
        ("net_buoyancy_before_N", "net buoyancy before / after trim [N]"),
        ("system_mass_kg", "system mass [kg]"),
    ]
    for ax, (key, title) in zip(axes.flat, panels, strict=True):
        if key == "funnel_margin_min_first":
            ax.bar(x - 0.2, values(key), 0.4, color=colors, label="1st")
            ax.bar(
                x + 0.2,
                values("funnel_margin_min_second"),
                0.4,
                color=colors,
                alpha=0.5,
                label="2nd",
            )
            ax.axhline(0.0, color="k", lw=0.8)
            ax.legend(fontsize=8)
        elif key == "net_buoyancy_before_N":
            ax.bar(x - 0.2, values(key), 0.4, color="tab:blue", label="before")
            ax.bar(x + 0.2, values("net_buoyancy_after_N"), 0.4, color="tab:orange", label="after")
            ax.axhline(0.0, color="k", lw=0.8)
            ax.legend(fontsize=8)
        else:
            ax.bar(x, values(key), color=colors)
        ax.set_title(title, fontsize=10)
        ax.set_xticks(x, names, rotation=30, ha="right", fontsize=8)
        ax.grid(axis="y", alpha=0.3)
    fig.suptitle("Arms compared (green: task completed, red: failed, gray: unreachable)")
    fig.tight_layout()
    path = out / "comparison.png"
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)
    return path
