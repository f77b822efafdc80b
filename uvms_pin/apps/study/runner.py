"""Run a study on ``dask.distributed`` into one Parquet table, resumably.

Layout of an output directory::

    study.toml          a copy of the study file (what was asked)
    study_inputs.json   the study settings and the digests of its base scenario and model
    results.parquet     THE table: one row per finished run, sorted by run index
    parts/<id>.parquet  rows finished since the last compaction (one file per run)
    rollouts/<id>/      rollouts, only with keep_rollouts

Every file is written to a temporary name and renamed (atomic on POSIX), so a crash or
Ctrl-C leaves the table as it was at its last compaction plus whole part files. On start
the table and the part files are merged (deduplicated by run id) and the recorded runs
are skipped: a rerun finishes the study without repeating or losing a run.

A row holds the run id, index, sample, seed, every parameter value (column = its path),
status (``ok``, ``FunnelViolation``, ``diverged`` for any other `SimulationError`,
``error`` for any other exception, with ``error`` the message), the violation's level,
component and time, derived quantities (net buoyancy, initial orientation error, actuator
saturation), every metric of `Rollout.metrics`, the run's wall time and host.
"""

from __future__ import annotations

import contextlib
import json
import logging
import math
import os
import signal
import socket
import sys
import threading
import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from uvms_pin.apps.study.identity import check_same_study, file_sha256, record_study_inputs
from uvms_pin.apps.study.spec import Run, Study
from uvms_pin.checks import check_memory
from uvms_pin.errors import ControllerError, FunnelViolation, SimulationError, StudyError
from uvms_pin.results.atomic import atomic_path

RESULTS_FILE = "results.parquet"
PARTS_DIR = "parts"
ROLLOUTS_DIR = "rollouts"
STATUSES = ("ok", "FunnelViolation", "diverged", "error")

RunFunction = Callable[[str, Run, "str | None"], dict[str, Any]]


# ---- one run (executes on a worker) --------------------------------------------------------


def execute_run(base: str, run: Run, rollout_dir: str | None = None) -> dict[str, Any]:
    """Load the base scenario with the run's overrides, scale the plant, simulate; a row.

    Never raises for a failed run: the status and message go in the row.
    """
    from uvms_pin.apps.study.plant import modify_plant
    from uvms_pin.scenario.load import load_scenario
    from uvms_pin.sim.run import simulate

    start = time.perf_counter()
    row = base_row(run)
    rollout = None
    try:
        scenario = modify_plant(load_scenario(base, run.overrides), run.plant)
        row["net_buoyancy_N"] = scenario.uvms.net_buoyancy_N
        try:
            rollout = simulate(scenario, progress=False)
        except FunnelViolation as exc:
            rollout = getattr(exc, "rollout", None)
            row.update(
                status="FunnelViolation",
                error=str(exc),
                violation_level=exc.level,
                violation_component=exc.component,
                violation_time_s=float(exc.time_s),
            )
        except ControllerError as exc:  # the controller raised: not a result, an error
            rollout = getattr(exc, "rollout", None)
            row.update(status="error", error=str(exc))
            cause = exc.__cause__
            row["traceback"] = exc.user_traceback or "".join(
                traceback.format_exception(cause, limit=8) if cause else ()
            )
        except SimulationError as exc:
            rollout = getattr(exc, "rollout", None)
            row.update(status="diverged", error=str(exc))
        if rollout is not None:
            row.update(rollout_quantities(rollout))
            row.update(rollout.metrics())
            if rollout_dir is not None:
                rollout.save(Path(rollout_dir) / run.run_id)
    except Exception as exc:  # a bug or a bad input in one run must not stop the study
        row.update(status="error", error=f"{type(exc).__name__}: {exc}")
        row["traceback"] = traceback.format_exc(limit=8)
    row["run_wall_time_s"] = time.perf_counter() - start
    return row


def base_row(run: Run) -> dict[str, Any]:
    """The columns every row has, whatever happened to the run."""
    row: dict[str, Any] = {
        "run_id": run.run_id,
        "run_index": run.index,
        "sample": run.sample,
        "seed": run.seed,
        "status": "ok",
        "error": "",
        "violation_level": "",
        "violation_component": "",
        "violation_time_s": math.nan,
        "host": socket.gethostname(),
    }
    for path, value in run.values.items():
        row[run.columns.get(path, path)] = (
            value if not isinstance(value, list) else json.dumps(value)
        )
    return row


def rollout_quantities(rollout) -> dict[str, float]:
    """Initial orientation error, and how often the actuators saturated."""
    out: dict[str, float] = {}
    s = rollout.signals
    if "e_x" in s and len(s["e_x"]):
        e_o = s["e_x"][0, 3:6]
        for name, value in zip(("roll", "pitch", "yaw"), e_o, strict=True):
            out[f"initial_error_{name}_rad"] = float(value)
        out["initial_orientation_error_max_rad"] = float(np.max(np.abs(e_o)))
    if "xi_x" in s and len(s["xi_x"]):
        out["initial_orientation_xi_max"] = float(np.max(np.abs(s["xi_x"][0, 3:6])))
    commanded = s.get("tau_commanded")
    if commanded is not None and len(commanded):
        clipped = np.abs(commanded - rollout.tau) > 1e-6 * np.maximum(1.0, np.abs(commanded))
        # surge, sway, heave, yaw: roll and pitch may be unactuated (always "clipped")
        out["vehicle_saturation_fraction"] = float(
            np.mean(np.any(clipped[:, [0, 1, 2, 5]], axis=1))
        )
        out["joint_saturation_fraction"] = float(np.mean(np.any(clipped[:, 6:], axis=1)))
    return out


def error_row(run: Run, exc: BaseException) -> dict[str, Any]:
    """The row of a run whose task itself failed (worker killed, unpicklable result...)."""
    row = base_row(run)
    row.update(status="error", error=f"{type(exc).__name__}: {exc}", host="")
    return row


# ---- the table -----------------------------------------------------------------------------


def _atomic_parquet(frame: pd.DataFrame, path: Path) -> None:
    with atomic_path(path) as tmp:
        frame.to_parquet(tmp, index=False)


#: memory of a table read into pandas per byte of its columns in the file (uncompressed):
#: the columns, their object strings and the copies concat and sorting make
_TABLE_EXPANSION = 4


def _read_parquet(path: Path) -> pd.DataFrame:
    import pyarrow.parquet as pq

    try:
        metadata = pq.ParquetFile(path).metadata
        size = sum(metadata.row_group(k).total_byte_size for k in range(metadata.num_row_groups))
        check_memory(
            _TABLE_EXPANSION * size,
            f"{path} ({metadata.num_rows} rows, {metadata.num_columns} columns) read into memory",
            "report on a machine with more memory, or split the study",
            StudyError,
        )
        return pd.read_parquet(path)
    except StudyError:
        raise
    except Exception as exc:  # pyarrow raises several types for a damaged file
        raise StudyError(
            f"{path}: not a readable Parquet table ({type(exc).__name__}: {exc}); "
            "it was not written by uvms-pin or was damaged: move it away and rerun"
        ) from exc


class ResultStore:
    """The rows of one output directory: the compacted table plus one part file per run."""

    def __init__(self, out: str | Path):
        self.out = Path(out)
        self.table_path = self.out / RESULTS_FILE
        self.parts = self.out / PARTS_DIR
        self.parts.mkdir(parents=True, exist_ok=True)
        for stale in self.parts.glob(".*.tmp"):  # an interrupted write, never renamed
            stale.unlink()

    def _part_files(self) -> list[Path]:
        return sorted(self.parts.glob("*.parquet"))

    def load(self) -> pd.DataFrame:
        """Every recorded row (table and parts), one per run id, sorted by run index."""
        frames = []
        if self.table_path.is_file():
            frames.append(_read_parquet(self.table_path))
        frames += [_read_parquet(p) for p in self._part_files()]
        frames = [f for f in frames if len(f)]
        if not frames:
            return pd.DataFrame()
        table = pd.concat(frames, ignore_index=True)
        # a part is newer than the table (a retried run, or a crash before its unlink)
        table = table.drop_duplicates("run_id", keep="last")
        return table.sort_values("run_index", kind="stable").reset_index(drop=True)

    def record(self, row: dict[str, Any]) -> None:
        """Durably add one row (a part file named after the run id)."""
        _atomic_parquet(pd.DataFrame([row]), self.parts / f"{row['run_id']}.parquet")

    def compact(self) -> pd.DataFrame:
        """Rewrite the table with every row, atomically; then drop the merged parts."""
        parts = self._part_files()
        table = self.load()
        if parts or not self.table_path.is_file():
            _atomic_parquet(table, self.table_path)
            for p in parts:
                p.unlink()
        return table


def load_results(out: str | Path) -> pd.DataFrame:
    """The study table of an output directory (parts not yet compacted included)."""
    out = Path(out)
    if not (out / RESULTS_FILE).is_file() and not (out / PARTS_DIR).is_dir():
        raise StudyError(f"{out}: no {RESULTS_FILE}: not a study output directory")
    return ResultStore(out).load()


# ---- the study -----------------------------------------------------------------------------


class Summary(dict):
    """Counts of a sweep: total, skipped (already recorded), run now, and per status."""


def _client(workers: int | None, scheduler: str | None):
    from dask.distributed import Client, LocalCluster

    if scheduler is not None:
        try:
            return Client(scheduler, timeout=30), None
        except (OSError, TimeoutError, ValueError) as exc:
            raise StudyError(
                f"--scheduler {scheduler}: cannot connect ({type(exc).__name__}: {exc}); "
                "is the scheduler running at that address?"
            ) from exc
    with _sigint_ignored_by_children():
        cluster = LocalCluster(
            n_workers=workers or os.cpu_count() or 1,
            threads_per_worker=1,
            processes=True,
            dashboard_address=":0",
            silence_logs=logging.ERROR,
        )
    return Client(cluster), cluster


@contextlib.contextmanager
def _sigint_ignored_by_children():
    """Start worker processes with Ctrl-C ignored (inherited, and Python keeps an ignored
    SIGINT): a terminal's Ctrl-C reaches the whole process group, and each worker would
    print its own KeyboardInterrupt traceback; this process alone handles it and closes
    the cluster."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def run_study(
    study: Study,
    out: str | Path,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    keep_rollouts: bool = False,
    progress: bool = True,
    retry_errors: bool = False,
    compact_every: int = 20,
    compact_interval_s: float = 60.0,
    run_fn: RunFunction = execute_run,
    on_result: Callable[[dict[str, Any]], None] | None = None,
) -> Summary:
    """Run every run of ``study`` not yet recorded in ``out``; return the counts.

    Args:
        workers: LocalCluster size (processes, 1 thread each); 0 runs serially in this
            process (no Dask; for debugging and tests). Default: the CPU count.
        scheduler: address of a running Dask scheduler (overrides ``workers``).
        keep_rollouts: save each run's rollout under ``out/rollouts/<run id>/``.
        retry_errors: rerun recorded runs whose status is ``error`` (not the funnel
            violations and divergences, which are results).
        compact_every, compact_interval_s: rewrite the table after this many new rows or
            this much time, whichever comes first (rows are durable before that anyway).
        run_fn: what each task executes (tests inject failures through it).
        on_result: called with each new row after it is recorded.
    """
    out = Path(out)
    store, recorded = _open_store(study, out)
    runs = study.runs()
    done_ids, counts = _recorded_runs(recorded, retry_errors)
    todo = [r for r in runs if r.run_id not in done_ids]
    base_sha = file_sha256(study.base)
    rollout_dir = str(out / ROLLOUTS_DIR) if keep_rollouts else None
    summary = Summary(total=len(runs), skipped=len(runs) - len(todo), run=0, **counts)
    if not todo:
        return summary

    bar = _progress_bar(study.name, len(runs), len(runs) - len(todo), progress, counts)
    compaction = _Compaction(store, compact_every, compact_interval_s)
    recorder = _Recorder(base_sha, counts, summary, bar, compaction, on_result)
    base = str(study.base)
    try:
        if workers == 0 and scheduler is None:
            for run in todo:
                recorder.record(run_fn(base, run, rollout_dir))
        else:
            _run_on_dask(todo, base, rollout_dir, run_fn, recorder.record, workers, scheduler)
    finally:
        bar.close()
        store.compact()
    return summary


def _open_store(study: Study, out: Path) -> tuple[ResultStore, pd.DataFrame]:
    """The output directory's store and its rows, compacted, after checking that they are
    rows of this study (before anything is written) and recording the study's inputs."""
    out.mkdir(parents=True, exist_ok=True)
    store = ResultStore(out)
    recorded = store.load()
    base_hashes = recorded.get("base_sha256", pd.Series(dtype=object)).dropna()
    check_same_study(out, study, set(base_hashes))  # before anything is written
    record_study_inputs(out, study)
    return store, store.compact()


def _recorded_runs(recorded: pd.DataFrame, retry_errors: bool) -> tuple[set[str], dict[str, int]]:
    """The ids of the recorded runs not to run again (with ``retry_errors``, the errors
    are run again), and their counts per status (every status of `STATUSES` included)."""
    done_ids: set[str] = set()
    counts = dict.fromkeys(STATUSES, 0)
    if len(recorded):
        keep = recorded
        if retry_errors:
            keep = recorded[recorded["status"] != "error"]
        done_ids = set(keep["run_id"])
        for status in keep["status"]:
            counts[status] = counts.get(status, 0) + 1
    return done_ids, counts


def _failures(counts: dict[str, int]) -> str:
    """The progress bar's postfix: the count of each status other than ok."""
    return " ".join(f"{k}={counts[k]}" for k in STATUSES[1:])


def _progress_bar(name: str, total: int, done: int, progress: bool, counts: dict[str, int]):
    """A tqdm bar over the runs (disabled without ``progress``), the recorded ones done."""
    from tqdm.auto import tqdm

    bar = tqdm(
        total=total,
        initial=done,
        unit="run",
        desc=name,
        disable=not progress,
        dynamic_ncols=True,
        # in a log file (nohup) one line every 30 s rather than a redraw per run
        mininterval=0.5 if sys.stderr.isatty() else 30.0,
    )
    bar.set_postfix_str(_failures(counts), refresh=False)
    return bar


@dataclass
class _Compaction:
    """Rewrites the table after ``every`` new rows or ``interval_s`` seconds since the
    last rewrite, whichever comes first."""

    store: ResultStore
    every: int
    interval_s: float
    since: int = 0
    last: float = field(default_factory=time.monotonic)

    def row_added(self) -> None:
        """Count one new row; rewrite the table if it is due."""
        self.since += 1
        if self.since >= self.every or time.monotonic() - self.last > self.interval_s:
            self.store.compact()
            self.since = 0
            self.last = time.monotonic()


@dataclass
class _Recorder:
    """Takes each finished run's row: stamps the base scenario's digest, stores it, counts
    it (``counts``, ``summary``, the progress bar), lets the table be compacted, then
    calls ``on_result``."""

    base_sha256: str
    counts: dict[str, int]
    summary: Summary
    bar: Any
    compaction: _Compaction
    on_result: Callable[[dict[str, Any]], None] | None

    def record(self, row: dict[str, Any]) -> None:
        """Record one finished run's row (see the class)."""
        row["base_sha256"] = self.base_sha256
        self.compaction.store.record(row)
        counts = self.counts
        counts[row["status"]] = counts.get(row["status"], 0) + 1
        self.summary["run"] += 1
        self.summary[row["status"]] = counts[row["status"]]
        self.bar.update(1)
        self.bar.set_postfix_str(_failures(counts), refresh=False)
        self.compaction.row_added()
        if self.on_result is not None:
            self.on_result(row)


def _run_on_dask(todo, base, rollout_dir, run_fn, finished, workers, scheduler) -> None:
    from dask.distributed import as_completed

    client, cluster = _client(workers, scheduler)
    futures = {}
    try:
        for run in todo:
            future = client.submit(
                run_fn, base, run, rollout_dir, key=f"uvms-run-{run.run_id}", pure=False
            )
            futures[future] = run
        for future in as_completed(futures):
            run = futures[future]
            try:
                row = future.result()
            except Exception as exc:  # the task itself failed (e.g. its worker died)
                row = error_row(run, exc)
            finished(row)
            future.release()
    finally:
        for future in futures:
            if not future.done():
                future.cancel()
        client.close()
        if cluster is not None:
            cluster.close()
