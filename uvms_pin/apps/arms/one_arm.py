"""One arm of the comparison: mount it, solve its initial configuration, trim, run.

The reference arm (``entry`` None) runs the scenario as it is. Any other arm is mounted
at the reference arm's mount point, rotated by ``mount_rpy``; its initial configuration
puts the tool tip where the reference tool tip is at the scenario's start
(:mod:`uvms_pin.apps.arms.initial`; "unreachable" rows stop there); the system is trimmed
at that configuration unless ``trim=None``; the scenario is loaded again with the merged
model (``OUT/models/NAME.urdf``), the initial joints, zero initial velocity and the
controller adapted to the arm (`controller.controller_overrides`), and run
(`outcome.run_scenario`).
"""

from __future__ import annotations

import math
import traceback
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from uvms_pin.apps.arms.controller import controller_overrides
from uvms_pin.apps.arms.initial import solve_initial_configuration
from uvms_pin.apps.arms.outcome import run_scenario
from uvms_pin.apps.arms.progress import ArmProgress
from uvms_pin.apps.arms.row import nan_row, write_row
from uvms_pin.apps.arms.settings import CompareSettings
from uvms_pin.errors import ScenarioError, UvmsPinError
from uvms_pin.model.mount.catalog import REFERENCE, ArmEntry, resolve_arm
from uvms_pin.model.mount.mount import MountResult, mount_arm_detailed
from uvms_pin.model.uvms import UVMS
from uvms_pin.results.atomic import write_text_atomic
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import Scenario


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
    row = nan_row(name if entry is None else entry.name)
    keep_dir = Path(out_dir) / row["arm"] if settings.keep_rollouts else None
    progress = ArmProgress(row["arm"], emit) if emit is not None else False
    job = _ArmJob(
        entry, scenario_path, out_dir, vehicle_urdf, mount_xyz, hull, settings, keep_dir, progress
    )
    try:
        _fill_row(row, job)
    except ScenarioError as exc:  # the scenario's task does not fit this arm
        row.update(status="scenario error", reason=f"{type(exc).__name__}: {exc}")
    except UvmsPinError as exc:
        row.update(status="model error", reason=f"{type(exc).__name__}: {exc}")
    except Exception as exc:  # a per-arm bug must not lose the other rows
        row.update(
            status="error",
            reason=f"{type(exc).__name__}: {exc} | {traceback.format_exc(limit=2)!r}",
        )
    write_row(row, keep_dir)
    return row


def _fill_row(row: dict, job: _ArmJob) -> None:
    """Mount, solve, trim and run one arm, filling ``row`` (raises on a model error)."""
    settings = job.settings
    overrides = settings.scenario_overrides
    vehicle_mass = _vehicle_mass(Path(job.vehicle_urdf))
    base = load_scenario(job.scenario_path, overrides)
    target = _start_tool_placement(base)
    if job.entry is None:
        _run_reference(row, job, base, vehicle_mass)
    else:
        _run_mounted(row, job, base, overrides, vehicle_mass, target)


def _vehicle_mass(urdf: Path) -> float:
    """The vehicle's mass [kg] (its URDF alone)."""
    model = pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer())
    return float(sum(i.mass for i in model.inertias))


def _start_tool_placement(base: Scenario) -> pin.SE3:
    """world_T_ee of the reference arm at the scenario's start: the task's target."""
    reference = base.uvms
    data = reference.model.createData()
    pin.framesForwardKinematics(reference.model, data, base.q0)
    return data.oMf[reference.ee_frame_id].copy()


def _untrimmed_columns(uvms: UVMS, vehicle_mass_kg: float) -> dict:
    """The row's joint count, masses [kg] and net buoyancy [N] of ``uvms`` as it is
    (no foam, no ballast: the buoyancy after trim is the one before)."""
    return dict(
        n_joints=uvms.n_arm_joints,
        arm_mass_kg=uvms.mass_kg - vehicle_mass_kg,
        system_mass_kg=uvms.mass_kg,
        net_buoyancy_before_N=uvms.net_buoyancy_N,
        net_buoyancy_after_N=uvms.net_buoyancy_N,
        foam_volume_L=0.0,
        ballast_kg=0.0,
    )


def _run_reference(row: dict, job: _ArmJob, base: Scenario, vehicle_mass: float) -> None:
    """The scenario as it is."""
    reference = base.uvms
    row.update(
        _untrimmed_columns(reference, vehicle_mass),
        initial_orientation_error_deg=0.0,
        derived_hydro_bodies=sum(b.params.derived for b in reference.hydro_bodies),
    )
    run_scenario(base, row, job.keep_dir, job.progress)
    row["reason"] = ("the scenario as it is; " + row["reason"]).rstrip("; ")


def _mount(job: _ArmJob, water_density_kg_m3: float, **trim) -> MountResult:
    """``job``'s arm on the vehicle (``trim``: the trim keywords of `mount_arm_detailed`)."""
    entry = job.entry
    pose = (np.asarray(job.mount_xyz), np.asarray(mount_rpy(job)))
    return mount_arm_detailed(
        job.vehicle_urdf,
        entry.urdf,
        pose,
        ee_link=entry.ee_link,
        arm_base_link=entry.arm_base_link,
        water_density_kg_m3=water_density_kg_m3,
        allow_dry_links=True,
        **trim,
    )


def mount_rpy(job: _ArmJob) -> tuple[float, float, float]:
    """How ``job``'s arm is bolted: the comparison's orientation, else the arm's own."""
    given = job.settings.mount_rpy
    return job.entry.mount_rpy_rad if given is None else given


def _run_mounted(
    row: dict, job: _ArmJob, base: Scenario, overrides: dict, vehicle_mass: float, target: pin.SE3
) -> None:
    """Mount ``job``'s arm, solve its initial configuration for ``target``, trim, run."""
    settings = job.settings
    density = base.uvms.water_density_kg_m3
    mounted = _mount(job, density)
    row.update(
        _untrimmed_columns(mounted.uvms, vehicle_mass),
        mount_rpy=tuple(mount_rpy(job)),
        derived_hydro_bodies=len(mounted.derived_bodies),
        dry_links=" ".join(mounted.dry_links),
    )
    ik = solve_initial_configuration(
        mounted.uvms,
        base.q0[:7],
        target,
        hull=job.hull,
        starts=settings.ik_starts,
        seed=settings.seed,
    )
    row["initial_orientation_error_deg"] = math.degrees(ik.orientation_error_rad)
    if not ik.reachable:
        row.update(status="unreachable", reason=ik.reason)
        return
    model_path = Path(job.out_dir) / "models" / f"{job.entry.name}.urdf"
    joints = mounted.uvms.arm_joints.positions(ik.q)
    mounted, trim_notes = _trimmed(row, job, mounted, joints, model_path, density)
    arm_overrides = {
        **overrides,
        "scenario.model": str(model_path.resolve()),
        "initial.joint_positions_rad": joints.tolist(),
        "initial.velocity": [0.0] * mounted.uvms.nv,
        **controller_overrides(
            base.raw.get("controller", {}), base.uvms, base.q0, mounted.uvms, ik.q
        ),
    }
    run_scenario(load_scenario(job.scenario_path, arm_overrides), row, job.keep_dir, job.progress)
    _add_notes(row, ik.orientation_error_rad, trim_notes)


def _trimmed(
    row: dict,
    job: _ArmJob,
    mounted: MountResult,
    q_arm: np.ndarray,
    model_path: Path,
    water_density_kg_m3: float,
) -> tuple[MountResult, str]:
    """The arm mounted again with foam and ballast for ``q_arm`` [rad] (the trim's columns
    into ``row``), its model saved at ``model_path``, and the trim's notes; without
    ``settings.trim``, ``mounted`` as it is (its model saved) and no notes."""
    if job.settings.trim is None:
        model_path.parent.mkdir(parents=True, exist_ok=True)
        write_text_atomic(model_path, mounted.urdf_text)
        return mounted, ""
    trimmed = _mount(
        job,
        water_density_kg_m3,
        trim=job.settings.trim,
        trim_joint_positions=q_arm,
        save_urdf=model_path,
    )
    report = trimmed.trim
    row.update(
        net_buoyancy_after_N=trimmed.uvms.net_buoyancy_N,
        system_mass_kg=trimmed.uvms.mass_kg,
        foam_volume_L=report.foam_volume_m3 * 1e3,
        ballast_kg=report.ballast_mass_kg,
        bg_cm=report.bg_after_m * 100.0,
    )
    return trimmed, "; ".join(report.notes)


def _add_notes(row: dict, orientation_error_rad: float, trim_notes: str) -> None:
    """Put the initial tool orientation error (above 1e-3 rad) before the row's reason
    and the trim's notes after it."""
    if orientation_error_rad > 1e-3:
        note = (
            f"initial tool orientation {math.degrees(orientation_error_rad):.1f} deg "
            "from the reference arm's (the arm cannot match it at the task's start point)"
        )
        row["reason"] = f"{note}; {row['reason']}" if row["reason"] else note
    if trim_notes:
        row["reason"] = f"{row['reason']}; trim: {trim_notes}".lstrip("; ")
