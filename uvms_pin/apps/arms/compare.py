"""Run the same task with several arms on the same vehicle and tabulate the outcome.

For a scenario (e.g. ``scenarios/realistic_force_tracking.toml``) whose model is a UVMS URDF:

1. The scenario's model is split into the vehicle and its arm (:func:`split_urdf`); the
   target of the task is the reference tool tip placement in the world at the scenario's
   start (the spring anchor: the spring attaches where the tip is at t = 0), with the
   paper's initial tool orientation.
2. Each arm is mounted at the reference arm's mount point (where its base is bolted, in the
   vehicle's frame: `split_urdf`'s ``mount_pose``), rotated by
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
   SimulationError), "error" (the controller raised) or "joint limits" if a joint left its limits during the run.
7. With ``keep_rollouts``, each arm's row (``row.json``: status, reason, trim) and, when it
   ran, its rollout, ``metrics.json`` and figures (the paper's funnel figures show which
   error left its funnel, and when) go to ``OUT/<arm>/``, as ``uvms-pin run`` writes them.

The reference row is the scenario itself, unchanged.
"""

from __future__ import annotations

import tempfile
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from uvms_pin.apps.arms.one_arm import run_one_arm
from uvms_pin.apps.arms.progress import done_line, print_to_stderr
from uvms_pin.apps.arms.row import COLUMNS
from uvms_pin.apps.arms.settings import CompareSettings
from uvms_pin.apps.arms.table import write_comparison
from uvms_pin.apps.workers import stop_pool, workers_signals
from uvms_pin.checks import check_memory
from uvms_pin.errors import ScenarioError
from uvms_pin.model.mount.catalog import REFERENCE, ArmEntry, resolve_arm
from uvms_pin.model.mount.hull import hull_box
from uvms_pin.model.mount.split import split_urdf
from uvms_pin.scenario.load import load_scenario

# COLUMNS, CompareSettings and write_comparison live in row, settings and table; they
# stay importable from here, where they were before the module was split
__all__ = ["COLUMNS", "CompareSettings", "compare_arms", "write_comparison"]


def compare_arms(
    scenario_path: str | Path,
    arms: Sequence[str | ArmEntry],
    out_dir: str | Path,
    settings: CompareSettings = CompareSettings(),  # noqa: B008 - frozen, immutable
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
    base = load_scenario(scenario_path, settings.scenario_overrides)
    if not base.uvms.n_arm_joints:
        raise ScenarioError(
            f"{scenario_path}: its model ({base.uvms.source}) is a vehicle without an arm: "
            "compare-arms mounts each arm where the scenario's arm is and runs the "
            "scenario's task with it; give a scenario whose model carries an arm"
        )
    _check_runs_fit(base, min(jobs, len(arms)))
    model_path = Path(base.uvms.source)
    for name in arms:  # fail early on names that are neither known nor files
        if name != REFERENCE:
            resolve_arm(name)
    with tempfile.TemporaryDirectory(prefix="uvms_pin_arms_") as tmp:
        split = split_urdf(model_path, tmp, first_arm_joint=base.uvms.arm_joint_names[0])
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
        if jobs > 1 and len(arms) > 1:
            rows = _run_in_processes(args, jobs, progress)
        else:
            rows = _run_in_turn(args, progress)
    write_comparison(rows, out, scenario=str(scenario_path), settings=settings)
    return rows


#: configuration and velocity entries an arm of the catalogue may add to the scenario's
#: (a 7-joint arm replacing a 4-joint one, continuous joints counted twice), and hulls (the
#: wet fractions logged: panda's 18 derived bodies against the reference arm's 5)
_MORE_ARM_ENTRIES = 16
_MORE_HULLS = 16


def _check_runs_fit(base, parallel: int) -> None:
    """ScenarioError before any arm runs if ``parallel`` runs' logs would not fit."""
    uvms, settings = base.uvms, base.settings
    check_memory(
        parallel
        * settings.log_bytes(
            uvms.nq + _MORE_ARM_ENTRIES,
            uvms.nv + _MORE_ARM_ENTRIES,
            len(uvms.surface_bodies) + _MORE_HULLS if base.plant.free_surface else 0,
        ),
        f"the logs of {parallel} arm runs at a time ({settings.n_log} samples each)",
        "shorten --duration, lengthen output.log_period_s or lower --jobs",
        ScenarioError,
    )


def _run_in_processes(
    args: list[tuple], jobs: int, progress: Callable[[str], None] | None
) -> list[dict]:
    """`run_one_arm` for each of ``args`` in ``jobs`` processes; the rows in order (the
    lines during a run go to stderr, the one when an arm is done to ``progress``)."""
    rows: list[dict] = []
    start = time.perf_counter()
    emit = print_to_stderr if progress else None
    pool = ProcessPoolExecutor(max_workers=jobs)
    try:
        with workers_signals():  # the first submit forks every worker
            futures = [pool.submit(run_one_arm, *a, emit) for a in args]
        for future in futures:
            rows.append(future.result())
            if progress:
                progress(done_line(rows[-1], start))
    except BaseException:  # Ctrl-C, SIGTERM: the workers stopped with the command
        stop_pool(pool)
        raise
    pool.shutdown(wait=True)
    return rows


def _run_in_turn(args: list[tuple], progress: Callable[[str], None] | None) -> list[dict]:
    """`run_one_arm` for each of ``args`` in this process, one after the other."""
    rows: list[dict] = []
    start = time.perf_counter()
    for a in args:
        if progress:
            label = a[0].name if isinstance(a[0], ArmEntry) else a[0]
            progress(f"{label}: running ({time.perf_counter() - start:.0f} s elapsed)")
        rows.append(run_one_arm(*a, progress))
        if progress:
            progress(done_line(rows[-1], start))
    return rows
